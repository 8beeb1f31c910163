// `pt render --part K/N`, `pt merge` and `pt render --resume` through the real binary: the merged
// image equals the one-machine render (bit for bit for regions), a part stopped by SIGTERM writes
// what it has and resumes to exactly the uninterrupted part, and every bad input (N = 0, K >= N,
// parts of different renders, a missing, duplicated, truncated or non-pt part) gets one line
// naming the file, exit status 2 and no output.
#include <doctest/doctest.h>

#include <cstring>
#include <regex>

#include "core/image/image.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

const std::string kCornell = std::string(PT_SOURCE_DIR) + "/scenes/cornell-box";
// 48x32: six 16x16 tiles; small enough to render in a blink.
const std::vector<std::string> kSettings = {"--res", "48x32", "--spp", "8", "--threads", "2"};

std::vector<std::string> render_args(const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"render", kCornell};
  args.insert(args.end(), kSettings.begin(), kSettings.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// Every channel of every pixel, and the channel names, bit for bit.
bool same_pixels(const pt::Image& a, const pt::Image& b) {
  return a.width == b.width && a.height == b.height && a.channels == b.channels &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

// A failed command: exit 2, one line "pt: error: ..." holding each of `expected`, and `folder`
// holds exactly `allowed` files afterwards (no output, no temporary).
void check_refused(const Outcome& o, const std::vector<std::string>& expected, const fs::path& folder, size_t allowed) {
  CAPTURE(o.err);
  CHECK(o.exited);
  CHECK(o.code == 2);
  REQUIRE(o.err_lines.size() == 1);
  CHECK(o.err_lines[0].rfind("pt: error: ", 0) == 0);
  for (const std::string& e : expected) CHECK(o.err_lines[0].find(e) != std::string::npos);
  CHECK(listing(folder).size() == allowed);
}

}  // namespace

TEST_CASE("region and sample parts merge into the one-machine image: EXR bit for bit, and PNG") {
  TempDir dir("pt-part");
  fs::path single = dir.path / "single.exr", single_png = dir.path / "single.png";
  std::vector<std::vector<std::string>> renders = {render_args({"-q", "-o", single.string()}),
                                                   render_args({"-q", "-o", single_png.string()})};
  for (const char* split : {"regions", "samples"}) {
    for (int k = 0; k < 3; ++k) {
      std::string part = (dir.path / (std::string(split) + std::to_string(k) + ".exr")).string();
      renders.push_back(render_args({"--part", std::to_string(k) + "/3", "--split", split, "-o", part}));
    }
  }
  std::vector<Outcome> done = run_pt_all(renders, dir);
  for (size_t i = 0; i < done.size(); ++i) {
    CAPTURE(done[i].err);
    REQUIRE(done[i].code == 0);
    if (i >= 2) {
      const char* split = i < 5 ? "regions" : "samples";
      CHECK(done[i].err.find("wrote part " + std::to_string((i - 2) % 3) + "/3 (" + split) != std::string::npos);
    }
  }
  for (const char* split : {"regions", "samples"}) {
    CAPTURE(split);
    std::vector<std::string> merge = {"merge"};
    for (int k : {2, 0, 1}) merge.push_back((dir.path / (std::string(split) + std::to_string(k) + ".exr")).string());  // any order
    fs::path merged = dir.path / (std::string(split) + ".exr");
    std::vector<std::string> args = merge;
    args.insert(args.end(), {"-o", merged.string()});
    Outcome o = run_pt(args, dir);
    CAPTURE(o.err);
    REQUIRE(o.code == 0);
    CHECK(o.err.find("merged 3 parts") != std::string::npos);
    pt::Image a = pt::read_image(merged.string()), b = pt::read_image(single.string());
    // Regions are bit-identical by construction; 8 samples of the Cornell box also sum exactly in
    // double, so the sample split is too (the general bound is tested in test_unit_part).
    CHECK(same_pixels(a, b));
    CHECK(a.metadata["pt:spp"] == "8");
    CHECK(a.metadata["pt:scene_hash"] == b.metadata["pt:scene_hash"]);
    CHECK(a.metadata.count("pt:part") == 0);
    // PNG: the same 8-bit image a one-machine PNG gets.
    fs::path png = dir.path / (std::string(split) + ".png");
    args = merge;
    args.insert(args.end(), {"-o", png.string(), "-q"});
    REQUIRE(run_pt(args, dir).code == 0);
    CHECK(same_pixels(pt::read_image(png.string()), pt::read_image(single_png.string())));
  }
}

TEST_CASE("a part stopped by SIGTERM keeps its samples; merge says it is short; --resume completes it exactly") {
  TempDir dir("pt-part");
  const std::vector<std::string> settings = {"--res", "48x32", "--spp", "3000", "--threads", "2", "--part", "1/2"};
  auto args = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = {"render", kCornell};
    a.insert(a.end(), settings.begin(), settings.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  fs::path part = dir.path / "part1.exr", err = dir.path / "term.txt";
  pid_t pid = start_pt(args({"-o", part.string()}), err);
  wait_for_text(err, "pass 1/");
  REQUIRE(::kill(pid, SIGTERM) == 0);
  Outcome o = finish(pid, err, 60);
  CAPTURE(o.err);
  REQUIRE(o.code == 143);
  pt::Image stopped = pt::read_image(part.string());
  long held = std::stol(stopped.metadata["pt:spp"]);
  CHECK(held >= 1);
  CHECK(held < 3000);
  CHECK(stopped.metadata["pt:samples"] == "0-3000");

  // Merged with its sibling, the short part gives a lower-sample image, and merge says so.
  fs::path part0 = dir.path / "part0.exr", whole = dir.path / "whole1.exr";
  pid_t reference = start_pt(args({"-q", "-o", whole.string()}), dir.path / "whole.txt");  // meanwhile
  REQUIRE(run_pt({"render", kCornell, "--res", "48x32", "--spp", "3000", "--part", "0/2", "--time", "0.01", "-q", "-o",
                  part0.string()},
                 dir)
              .code == 0);
  fs::path merged = dir.path / "short.exr";
  o = run_pt({"merge", part0.string(), part.string(), "-o", merged.string()}, dir);
  CAPTURE(o.err);
  CHECK(o.code == 0);
  CHECK(std::regex_search(o.err, std::regex("warning: " + part.string() + ": part 1/2 holds " + std::to_string(held))));
  CHECK(o.err.find("2 short") != std::string::npos);
  pt::Image short_image = pt::read_image(merged.string());
  CHECK(std::stol(short_image.metadata["pt:spp"]) >= 1);
  CHECK(std::stol(short_image.metadata["pt:spp"]) < 3000);

  // Resumed in place, then compared with the part rendered without a stop.
  o = run_pt(args({"--resume", part.string(), "-o", part.string()}), dir, 120);
  CAPTURE(o.err);
  REQUIRE(o.code == 0);
  CHECK(o.err.find("resuming part 1/2 from " + part.string() + ", which holds " + std::to_string(held)) != std::string::npos);
  REQUIRE(finish(reference, dir.path / "whole.txt", 120).code == 0);
  pt::Image resumed = pt::read_image(part.string()), uninterrupted = pt::read_image(whole.string());
  CHECK(same_pixels(resumed, uninterrupted));
  CHECK(resumed.metadata["pt:spp"] == "3000");
  // Resuming a complete part in place has nothing to do.
  o = run_pt(args({"--resume", part.string(), "-o", part.string()}), dir);
  CHECK(o.code == 0);
  CHECK(o.err.find("nothing to do") != std::string::npos);
}

TEST_CASE("bad --part, --split and --resume: one line, exit 2, nothing written") {
  TempDir dir("pt-part");
  fs::path good = dir.path / "good0.exr", plain = dir.path / "plain.exr";
  for (const Outcome& o : run_pt_all({render_args({"--part", "0/2", "-q", "-o", good.string()}),
                                      render_args({"-q", "-o", plain.string()})},
                                     dir)) {
    REQUIRE(o.code == 0);
  }
  fs::path out_dir = dir.path / "out";
  fs::create_directories(out_dir);
  std::string out = (out_dir / "o.exr").string();
  struct Case {
    std::vector<std::string> extra;
    std::vector<std::string> expected;
  };
  std::vector<Case> cases = {
      {{"--part", "0/0", "-o", out}, {"--part", "0/0", "at least 1"}},
      {{"--part", "4/4", "-o", out}, {"--part", "4/4"}},
      {{"--part", "-1/4", "-o", out}, {"--part"}},
      {{"--part", "x", "-o", out}, {"--part", "K/N"}},
      {{"--part", "0/2", "--split", "diagonal", "-o", out}, {"--split"}},
      {{"--part", "0/7", "-o", out}, {"--part", "6 tiles"}},  // 48x32 has 6 tiles of 16x16
      {{"--part", "0/9", "--split", "samples", "-o", out}, {"--part", "8 samples"}},
      {{"--part", "0/2", "-o", (out_dir / "o.png").string()}, {"o.png", "EXR"}},
      {{"--resume", (dir.path / "nope.exr").string(), "-o", out}, {"nope.exr", "no such file"}},
      {{"--resume", plain.string(), "-o", out}, {plain.string(), "not a pt part"}},
      {{"--resume", good.string(), "--seed", "9", "-o", out}, {good.string(), "pt:seed"}},
      {{"--resume", good.string(), "--part", "1/2", "-o", out}, {good.string(), "part 0/2"}},
  };
  std::vector<std::vector<std::string>> commands;
  for (const Case& c : cases) commands.push_back(render_args(c.extra));
  std::vector<Outcome> outcomes = run_pt_all(commands, dir);
  for (size_t i = 0; i < cases.size(); ++i) {
    std::string command;
    for (const std::string& a : cases[i].extra) command += a + " ";
    CAPTURE(command);
    check_refused(outcomes[i], cases[i].expected, out_dir, 0);
  }
}

TEST_CASE("pt merge refuses parts of different renders, missing, duplicated, truncated and non-pt files") {
  TempDir dir("pt-part");
  std::vector<std::vector<std::string>> renders;
  auto part = [&](const std::string& name, std::vector<std::string> extra) {
    std::string path = (dir.path / name).string();
    extra.insert(extra.end(), {"-q", "-o", path});
    renders.push_back(render_args(extra));
    return path;
  };
  std::string p0 = part("p0.exr", {"--part", "0/3"}), p1 = part("p1.exr", {"--part", "1/3"}),
              p2 = part("p2.exr", {"--part", "2/3"});
  std::string seeded = part("seeded.exr", {"--part", "2/3", "--seed", "4"});
  std::string samples = part("samples.exr", {"--part", "2/3", "--split", "samples"});
  std::string four = part("four.exr", {"--part", "2/4"});
  // Another scene: the same box with one colour changed in its material file.
  fs::create_directories(dir.path / "other");
  for (const char* f : {"scene.json", "cornell-box.obj", "cornell-box.mtl"}) fs::copy_file(kCornell + "/" + f, dir.path / "other" / f);
  { std::ofstream(dir.path / "other" / "cornell-box.mtl", std::ios::app) << "\n# changed\n"; }
  std::string other = (dir.path / "other-part.exr").string();
  {
    std::vector<std::string> a = {"render", (dir.path / "other").string()};
    a.insert(a.end(), kSettings.begin(), kSettings.end());
    a.insert(a.end(), {"--part", "2/3", "-q", "-o", other});
    renders.push_back(a);
  }
  std::string plain = part("plain.exr", {});
  for (const Outcome& o : run_pt_all(renders, dir)) {
    CAPTURE(o.err);
    REQUIRE(o.code == 0);
  }
  std::string text = read_file(p2);
  std::string truncated = dir.write("truncated.exr", text.substr(0, text.size() * 2 / 3));
  std::string junk = dir.write("junk.exr", "not an image at all\n");

  fs::path out_dir = dir.path / "merged";
  fs::create_directories(out_dir);
  std::string out = (out_dir / "m.exr").string();
  struct Case {
    std::vector<std::string> parts;
    std::vector<std::string> expected;
  };
  std::vector<Case> cases = {
      {{p0, p1, other}, {other, "pt:scene_hash"}},
      {{p0, p1, seeded}, {seeded, "pt:seed"}},
      {{p0, p1, samples}, {samples, "pt:split"}},
      {{p0, p1, four}, {four, "2/4"}},
      {{p0, p1}, {"missing part 2/3"}},
      {{p0, p1, p2, p1}, {p1, "duplicates part 1/3"}},
      {{p0, p1, truncated}, {truncated}},
      {{p0, p1, junk}, {junk}},
      {{p0, p1, plain}, {plain, "not a pt part"}},
      {{p0, p1, p2, "-o", (out_dir / "m.txt").string()}, {"m.txt"}},
  };
  std::vector<std::vector<std::string>> commands;
  for (const Case& c : cases) {
    std::vector<std::string> args = {"merge"};
    args.insert(args.end(), c.parts.begin(), c.parts.end());
    if (std::find(args.begin(), args.end(), "-o") == args.end()) args.insert(args.end(), {"-o", out});
    commands.push_back(args);
  }
  std::vector<Outcome> outcomes = run_pt_all(commands, dir);
  for (size_t i = 0; i < cases.size(); ++i) {
    std::string command;
    for (const std::string& a : commands[i]) command += a + " ";
    CAPTURE(command);
    check_refused(outcomes[i], cases[i].expected, out_dir, 0);
  }
  // And the three good parts do merge.
  Outcome o = run_pt({"merge", p0, p1, p2, "-o", out}, dir);
  CHECK(o.code == 0);
  CHECK(listing(out_dir) == std::vector<std::string>{"m.exr"});
}
