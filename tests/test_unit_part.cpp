// Split renders (renderer/farm/part.h), their part files (part_file.h), the merge (merge.h) and resume,
// against the one-machine render of the same settings: regions merge bit for bit, sample ranges
// within the bound merge.h derives, a part survives its EXR bit for bit, and a render stopped
// anywhere (between passes or inside one) and resumed equals the uninterrupted render exactly.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include "core/util/error.h"
#include "renderer/render/job.h"
#include "renderer/farm/merge.h"
#include "renderer/farm/part_file.h"
#include "temp_dir.h"

using namespace pt;

namespace {

// The Cornell box, small and with ragged edge tiles (40 is not a multiple of 16).
Job cornell_job(const std::optional<std::string>& part = {}, const std::string& split = "regions", int spp = 12) {
  JobOptions o;
  o.scene_path = std::string(PT_SOURCE_DIR) + "/scenes/cornell-box/scene.json";
  o.resolution = "40x24";
  o.spp = spp;
  o.part = part;
  o.split = kSplitNames.parse(split);
  return prepare_job(o);
}

bool same_pixel(const Film::Pixel& a, const Film::Pixel& b) {
  return std::memcmp(a.sum, b.sum, sizeof a.sum) == 0 && std::memcmp(a.sum_sq, b.sum_sq, sizeof a.sum_sq) == 0 &&
         a.count == b.count && a.nonfinite == b.nonfinite;
}

// Every pixel of two films bit for bit; returns how many differ.
int differing_pixels(const Film& a, const Film& b) {
  REQUIRE(a.width() == b.width());
  REQUIRE(a.height() == b.height());
  int differ = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) differ += !same_pixel(a.pixel(x, y), b.pixel(x, y));
  }
  return differ;
}

// Floats apart, counted in units in the last place (both finite, same sign or zero).
int64_t ulps(float a, float b) {
  auto key = [](float f) {
    int32_t i = std::bit_cast<int32_t>(f);
    return i < 0 ? int64_t{INT32_MIN} - i : int64_t{i};
  };
  return std::llabs(key(a) - key(b));
}

// Wraps an integrator: returns NaN for some samples (chosen by the ray, so the same samples in
// every render), and raises `cancel` after `stop_after` calls, in the middle of a pass.
class StoppingIntegrator : public Integrator {
 public:
  StoppingIntegrator(const Integrator& inner, std::atomic<bool>* cancel, int64_t stop_after)
      : inner_(inner), cancel_(cancel), stop_after_(stop_after) {}
  Spectrum Li(const Ray& ray, const Scene& scene, const Accel& accel, Sampler& sampler, SampleInfo& info) const override {
    if (cancel_ && calls_.fetch_add(1) + 1 == stop_after_) cancel_->store(true);
    Spectrum L = inner_.Li(ray, scene, accel, sampler, info);
    if ((std::bit_cast<uint32_t>(ray.d.x) & 31u) == 7u) return Spectrum(std::numeric_limits<float>::quiet_NaN());
    return L;
  }

 private:
  const Integrator& inner_;
  std::atomic<bool>* cancel_;
  int64_t stop_after_;
  mutable std::atomic<int64_t> calls_{0};
};

}  // namespace

TEST_CASE("--part K/N: N = 0, K >= N and malformed values are refused") {
  CHECK(parse_part("0/4", SplitKind::kRegions).index == 0);
  CHECK(parse_part("3/4", SplitKind::kSamples).count == 4);
  CHECK(parse_part("0/1", SplitKind::kRegions).name() == "0/1");
  for (const char* bad : {"0/0", "4/4", "5/4", "-1/4", "1", "1/", "/4", "a/b", "1/4/5", " 1/4", "99999999/100000000"}) {
    CAPTURE(bad);
    CHECK_THROWS_AS(parse_part(bad, SplitKind::kRegions), Error);
  }
  // Empty parts are refused before any work: more region parts than tiles, more sample parts than spp.
  CHECK_THROWS_AS(check_part(parse_part("0/7", SplitKind::kRegions), 40, 24, 16), Error);  // 3x2 tiles
  CHECK_NOTHROW(check_part(parse_part("0/6", SplitKind::kRegions), 40, 24, 16));
  CHECK_THROWS_AS(check_part(parse_part("0/17", SplitKind::kSamples), 40, 24, 16), Error);
  CHECK_NOTHROW(check_part(parse_part("0/16", SplitKind::kSamples), 40, 24, 16));
}

TEST_CASE("region parts cover every pixel exactly once, with nearly equal tile counts") {
  struct Case {
    int w, h, step;  // step: pixels checked along each axis (the frame's size: one per tile corner)
    std::vector<int> parts;
  };
  for (const Case& c : {Case{40, 24, 1, {1, 2, 3, 5, 6}}, Case{17, 3, 1, {1, 2}}, Case{200, 120, 1, {2, 3, 7, 16, 40, 104}},
                        Case{1920, 1080, PartRegion::kTile, {10, 16, 100}}}) {
    int tiles = PartRegion(Part{SplitKind::kRegions, 0, 2}, c.w, c.h).tiles();
    for (int n : c.parts) {
      REQUIRE(n <= tiles);
      CAPTURE(c.w);
      CAPTURE(n);
      std::vector<PartRegion> regions;
      for (int k = 0; k < n; ++k) regions.emplace_back(Part{SplitKind::kRegions, k, n}, c.w, c.h);
      std::vector<int> owned_tiles(n, 0);
      bool once = true;
      for (int y = 0; y < c.h; y += c.step) {
        for (int x = 0; x < c.w; x += c.step) {
          int owners = 0, owner = -1;
          for (int k = 0; k < n; ++k) {
            if (regions[k].contains(x, y)) ++owners, owner = k;
          }
          once = once && owners == 1;
          if (owners == 1 && x % PartRegion::kTile == 0 && y % PartRegion::kTile == 0) ++owned_tiles[owner];
        }
      }
      CHECK(once);
      auto [lo, hi] = std::minmax_element(owned_tiles.begin(), owned_tiles.end());
      CHECK(*lo == tiles / n);
      CHECK(*hi == (tiles + n - 1) / n);
    }
  }
}

TEST_CASE("sample parts cover [0, spp) once, in order") {
  for (int spp : {1, 7, 64, 1000}) {
    for (int n = 1; n <= std::min(spp, 33); ++n) {
      int next = 0;
      for (int k = 0; k < n; ++k) {
        SampleRange r = part_samples(Part{SplitKind::kSamples, k, n}, spp);
        CHECK(r.begin == next);
        CHECK(r.size() >= spp / n);
        CHECK(r.size() <= (spp + n - 1) / n);
        next = r.end;
      }
      CHECK(next == spp);
    }
  }
  // Regions and whole renders take every sample.
  CHECK(part_samples(Part{SplitKind::kRegions, 1, 3}, 64).name() == "0-64");
  CHECK(part_samples(std::nullopt, 64).name() == "0-64");
}

TEST_CASE("region parts merge into the one-machine render bit for bit") {
  Job whole = cornell_job();
  RenderResult single = render(whole, {});
  for (int n : {2, 5}) {
    CAPTURE(n);
    Film merged(40, 24);
    for (int k = 0; k < n; ++k) {
      Job part = cornell_job(std::to_string(k) + "/" + std::to_string(n));
      RenderResult r = render(part, {});
      // The part holds nothing outside its region.
      PartRegion region(part.render.part, 40, 24);
      for (int y = 0; y < 24; ++y) {
        for (int x = 0; x < 40; ++x) {
          if (!region.contains(x, y)) CHECK(r.film.taken(x, y) == 0);
        }
      }
      merged.merge(r.film);
    }
    CHECK(differing_pixels(merged, single.film) == 0);
    Image a = merged.to_image(true), b = single.film.to_image(true);
    CHECK(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0);
  }
}

TEST_CASE("sample-range parts merge into the one-machine render within merge.h's bound") {
  const int spp = 240;  // enough samples that the two orders of addition round differently
  Job whole = cornell_job({}, "samples", spp);
  RenderResult single = render(whole, {});
  Film merged(40, 24);
  for (int k = 0; k < 5; ++k) {
    Job part = cornell_job(std::to_string(k) + "/5", "samples", spp);
    RenderResult r = render(part, {});
    SampleRange range = part_samples(part.render.part, spp);
    CHECK(r.film.min_count() + 0u <= static_cast<uint32_t>(range.size()));
    CHECK(r.film.max_count() == static_cast<uint32_t>(range.size()));
    merged.merge(r.film);
  }
  Image a = merged.to_image(true), b = single.film.to_image(true);
  int64_t worst_mean = 0;
  double worst_variance = 0;  // in units of the allowed error
  int differ = 0;
  for (int y = 0; y < 24; ++y) {
    for (int x = 0; x < 40; ++x) {
      CHECK(merged.count(x, y) == single.film.count(x, y));
      for (int c = 0; c < 3; ++c) {
        worst_mean = std::max(worst_mean, ulps(a.at(x, y, c), b.at(x, y, c)));
        differ += a.at(x, y, c) != b.at(x, y, c);
        double v = b.at(x, y, 3 + c), m = b.at(x, y, c), n = single.film.count(x, y);
        float ulp = std::nextafter(std::max(a.at(x, y, 3 + c), b.at(x, y, 3 + c)), INFINITY) -
                    std::max(a.at(x, y, 3 + c), b.at(x, y, 3 + c));
        double allowed = variance_merge_bound(v, m, n) + ulp;
        worst_variance = std::max(worst_variance, std::abs(double(a.at(x, y, 3 + c)) - double(b.at(x, y, 3 + c))) / allowed);
      }
    }
  }
  MESSAGE("sample merge: " << differ << " of " << 40 * 24 * 3 << " means differ, by at most " << worst_mean
                           << " ulp; variance error at most " << worst_variance << " of its bound");
  CHECK(worst_mean <= 1);
  CHECK(worst_variance <= 1.0);
}

TEST_CASE("film merge of sample ranges: within merge.h's bound where the two orders of addition do round differently") {
  // Samples spanning 12 decades (fireflies beside near-black paths): their double sums are not
  // exact, so one-by-one and part-by-part addition differ, which the render above rarely shows.
  const int width = 32, height = 8, n = 4096;
  const int cuts[] = {0, 517, 1024, 1999, 2048, 3001, 4000, n};
  Film single(width, height), merged(width, height);
  std::vector<Film> parts(std::size(cuts) - 1, Film(width, height));
  uint64_t state = 0x9e3779b97f4a7c15ULL;
  auto uniform = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1p-53;
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      size_t part = 0;
      for (int i = 0; i < n; ++i) {
        while (i >= cuts[part + 1]) ++part;
        Spectrum L;
        for (int c = 0; c < 3; ++c) L[c] = static_cast<float>(std::pow(10.0, -8 + 12 * uniform()));
        single.add(x, y, L);
        parts[part].add(x, y, L);
      }
    }
  }
  for (const Film& p : parts) merged.merge(p);
  Image a = merged.to_image(true), b = single.to_image(true);
  int64_t worst_mean = 0;
  double worst_variance = 0;
  int differ = 0, variance_differ = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        worst_mean = std::max(worst_mean, ulps(a.at(x, y, c), b.at(x, y, c)));
        differ += a.at(x, y, c) != b.at(x, y, c);
        float va = a.at(x, y, 3 + c), vb = b.at(x, y, 3 + c);
        variance_differ += va != vb;
        float ulp = std::nextafter(std::max(va, vb), INFINITY) - std::max(va, vb);
        double allowed = variance_merge_bound(vb, b.at(x, y, c), n) + ulp;
        worst_variance = std::max(worst_variance, std::abs(double(va) - double(vb)) / allowed);
      }
    }
  }
  MESSAGE("synthetic merge: " << differ << " of " << width * height * 3 << " means and " << variance_differ
                              << " variances differ; means by at most " << worst_mean << " ulp, variances by at most "
                              << worst_variance << " of the bound");
  CHECK(worst_mean <= 1);
  CHECK(worst_variance <= 1.0);
  // The sums do differ (else this test would show nothing about the bound).
  int sums_differ = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) sums_differ += !same_pixel(merged.pixel(x, y), single.pixel(x, y));
  }
  CHECK(sums_differ > width * height / 2);
}

TEST_CASE("a part survives its EXR bit for bit, and the files merge in any order") {
  TempDir dir("pt-part");
  Job whole = cornell_job({}, "samples");
  RenderResult single = render(whole, {});
  std::vector<std::string> paths;
  Film in_order(40, 24);
  for (int k = 0; k < 3; ++k) {
    Job job = cornell_job(std::to_string(k) + "/3", "samples");
    RenderResult r = render(job, {});
    std::string path = (dir.path / ("part" + std::to_string(k) + ".exr")).string();
    write_part(path, r.film, *job.render.part, image_metadata(job, r));
    PartFile back = read_part(path);
    CHECK(differing_pixels(back.film, r.film) == 0);
    CHECK(back.part.index == k);
    CHECK(back.samples.name() == part_samples(job.render.part, 12).name());
    in_order.merge(r.film);
    paths.push_back(path);
  }
  std::vector<std::string> reversed(paths.rbegin(), paths.rend());
  MergedParts merged = merge_parts(reversed);
  CHECK(differing_pixels(merged.film, in_order) == 0);
  CHECK(merged.short_parts.empty());
  CHECK(merged.metadata.count("pt:part") == 0);
  CHECK(merged.metadata["pt:spp"] == "12");
  CHECK(merged.metadata["pt:scene_hash"] == image_metadata(whole, single)["pt:scene_hash"]);

  // Values a film can hold that a float cannot: denormal and huge doubles, dropped samples.
  Job job = cornell_job("0/1", "samples");
  RenderResult r = render(job, {});
  Film odd = r.film;
  odd.pixel(0, 0).sum[0] = 4.9406564584124654e-324;
  odd.pixel(1, 0).sum[1] = 12 * 3.4028234663852886e38;  // as large as 12 float samples can add up to
  odd.pixel(1, 0).sum_sq[2] = 1e77 + 1e61;
  odd.pixel(2, 0).sum[2] = 0.1 + 0.2;
  odd.pixel(3, 0).count = 5;
  odd.pixel(3, 0).nonfinite = 7;
  std::string path = (dir.path / "odd.exr").string();
  write_part(path, odd, *job.render.part, image_metadata(job, r));
  CHECK(differing_pixels(read_part(path).film, odd) == 0);
}

TEST_CASE("merge refuses mixed renders, duplicates and missing parts, naming the file") {
  TempDir dir("pt-part");
  auto write = [&](const std::string& name, const std::string& part, const std::string& split, int spp) {
    Job job = cornell_job(part, split, spp);
    RenderResult r = render(job, {});
    std::string path = (dir.path / name).string();
    write_part(path, r.film, *job.render.part, image_metadata(job, r));
    return path;
  };
  std::string a0 = write("a0.exr", "0/2", "regions", 4), a1 = write("a1.exr", "1/2", "regions", 4);
  std::string other_spp = write("b1.exr", "1/2", "regions", 8);
  std::string other_split = write("c1.exr", "1/2", "samples", 4);
  std::string three = write("d1.exr", "1/3", "regions", 4);
  auto refuses = [](const std::vector<std::string>& paths, const std::string& offender, const std::string& words) {
    try {
      merge_parts(paths);
      FAIL("merged " << paths.size() << " parts that it should have refused");
    } catch (const Error& e) {
      std::string what = e.what();
      CAPTURE(what);
      CHECK(what.find(offender) != std::string::npos);
      CHECK(what.find(words) != std::string::npos);
      CHECK(what.find('\n') == std::string::npos);
    }
  };
  CHECK_NOTHROW(merge_parts({a0, a1}));
  refuses({a0, other_spp}, other_spp, "pt:frame_spp");
  refuses({a0, other_split}, other_split, "pt:split");
  refuses({a0, three}, three, "3");
  refuses({a0, a0}, a0, "duplicates part 0/2");
  refuses({a1}, "0/2", "missing part");
  // Not a part: an ordinary render, and a truncated part.
  Job job = cornell_job();
  RenderResult r = render(job, {});
  Image plain = r.film.to_image(true);
  plain.metadata = image_metadata(job, r);
  std::string plain_path = (dir.path / "plain.exr").string();
  write_image(plain_path, plain);
  refuses({a0, plain_path}, plain_path, "not a pt part");
  std::ifstream in(a1, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string truncated = (dir.path / "truncated.exr").string();
  {
    std::ofstream out(truncated, std::ios::binary);
    out << text.substr(0, text.size() / 2);
  }
  refuses({a0, truncated}, truncated, "");
}

TEST_CASE("a render stopped between or inside passes and resumed equals the uninterrupted render, bit for bit") {
  for (const char* split : {"regions", "samples"}) {
    CAPTURE(split);
    Job job = cornell_job("1/3", split, 12);
    StoppingIntegrator plain(*job.integrator, nullptr, 0);
    RenderResult full = render(*job.scene, *job.accel, plain, job.render, {});
    uint32_t dropped = 0;
    for (int y = 0; y < 24; ++y) {
      for (int x = 0; x < 40; ++x) dropped += full.film.pixel(x, y).nonfinite;
    }
    CHECK(dropped > 0);  // the wrapper's NaNs are counted, and must be resumed past correctly

    // Stopped inside a pass (single thread: the stop lands at a known sample), resumed twice.
    for (int64_t stop_after : {1, 150, 333, 1000}) {
      CAPTURE(stop_after);
      std::atomic<bool> cancel{false};
      StoppingIntegrator stopping(*job.integrator, &cancel, stop_after);
      RenderControl control;
      control.threads = 1;
      control.tile_size = 8;  // the stop falls inside a 16x16 part tile, too
      control.cancel = &cancel;
      RenderResult first = render(*job.scene, *job.accel, stopping, job.render, control);
      REQUIRE(first.interrupted);
      uint32_t lo = UINT32_MAX, hi = 0;
      PartRegion region(job.render.part, 40, 24);
      for (int y = 0; y < 24; ++y) {
        for (int x = 0; x < 40; ++x) {
          if (!region.contains(x, y)) continue;
          lo = std::min(lo, first.film.taken(x, y));
          hi = std::max(hi, first.film.taken(x, y));
        }
      }
      CHECK(hi <= lo + 1);
      RenderControl again;
      again.resume = &first.film;
      RenderResult second = render(*job.scene, *job.accel, plain, job.render, again);
      CHECK_FALSE(second.interrupted);
      CHECK(differing_pixels(second.film, full.film) == 0);
    }
    // Stopped between passes by the time budget's sibling, on_pass, then resumed through a file.
    std::atomic<bool> cancel{false};
    RenderControl control;
    control.cancel = &cancel;
    control.on_pass = [&](int done, int, double, uint64_t) {
      if (done == 2) cancel = true;
    };
    RenderResult first = render(*job.scene, *job.accel, plain, job.render, control);
    CHECK(first.passes == 2);
    TempDir dir("pt-part");
    std::string path = (dir.path / "short.exr").string();
    write_part(path, first.film, *job.render.part, image_metadata(job, first));
    PartFile part = read_part(path);
    RenderControl again;
    again.resume = &part.film;
    RenderResult second = render(*job.scene, *job.accel, plain, job.render, again);
    CHECK(differing_pixels(second.film, full.film) == 0);
    // A short part merges, and says so.
    Job other = cornell_job(std::string("0/3"), split, 12), last = cornell_job(std::string("2/3"), split, 12);
    RenderResult r0 = render(other, {}), r2 = render(last, {});
    write_part((dir.path / "p0.exr").string(), r0.film, *other.render.part, image_metadata(other, r0));
    write_part((dir.path / "p2.exr").string(), r2.film, *last.render.part, image_metadata(last, r2));
    MergedParts merged = merge_parts({(dir.path / "p0.exr").string(), path, (dir.path / "p2.exr").string()});
    REQUIRE(merged.short_parts.size() == 1);
    CHECK(merged.short_parts[0].find(path) != std::string::npos);
    CHECK(merged.short_parts[0].find("holds 2 of its") != std::string::npos);
  }
}
