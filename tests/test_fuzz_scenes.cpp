// A seeded mutation fuzzer over the example scenes' inputs (issue 11): each mutant is one example
// scene with one of its input files (OBJ, MTL, glTF, GLB, PLY, JSON scene file, texture or environment map)
// changed by a few random mutations (for glTF, GLB and PLY files, half the time inside a base64
// buffer, the GLB's JSON chunk or the PLY header: mutate_file), run through `pt info` and `pt render`. Every run must end
// with exit 0 or 2 (bad input), within its time limit, without a sanitizer report (CI runs this in
// the ASan+UBSan build, build-asan), with every printed line escaped and capped, with a readable
// image after exit 0 and no image after a failure, and no temporary file left anywhere.
//
// Reproducible: mutant i depends only on (seed, i), so one failure reruns alone with
//   PT_FUZZ_SEED=<seed> PT_FUZZ_FIRST=<i> PT_FUZZ_COUNT=1 build-asan/tests/test_fuzz_scenes
// and PT_FUZZ_KEEP=<folder> keeps each failing mutant's whole scene there. PT_FUZZ_COUNT defaults
// to PT_FUZZ_DEFAULT_COUNT (tests/CMakeLists.txt: more in the sanitizer build, which is what CI's
// budget pays for), PT_FUZZ_SEED to 11. PT_FUZZ_ONLY=.glb,.gltf,.ply (extensions, comma-separated)
// mutates only inputs of those kinds, for a campaign on some formats (a seed then names other
// mutants than without it).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "core/scene/loader.h"
#include "gltf_text.h"
#include "run_pt.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

// SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number generators", 2014):
// our own, so that a seed means the same mutants with any standard library.
struct Rng {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  size_t below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(next() % n); }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[below(v.size())];
  }
};

uint64_t env_number(const char* name, uint64_t fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtoull(v, nullptr, 10) : fallback;
}

// Values that have broken parsers before: non-finite, beyond float, beyond int, signs, empty.
const std::vector<std::string> kNumbers = {
    "nan", "-nan", "inf", "-inf", "1e38", "-1e38", "3.5e38", "1e308", "1e-45", "1e-320", "0", "-0", "-1", "1",
    "2", "1e18", "-1e15", "1e15", "4294967295", "4294967296", "2147483648", "-2147483649", "18446744073709551616",
    "99999999999999999999999999", "0x7f", "1e", "-", ".", "+", "1.5.5", "1e+", "0000000000000000000000001"};
// Replacements for words: names of nothing, of devices and of folders, control characters and
// terminal escapes (which must never reach the terminal), keywords out of place, JSON syntax.
const std::vector<std::string> kWords = {
    "", std::string(300, 'A'), "\x1b[31mred\x1b[0m", "a\rb", "a\tb", "\x01\x7f\xc3", "/dev/zero", "..", "/",
    "missing.png", "missing.obj", "scene.json", "f", "v", "vt", "vn", "mtllib", "usemtl", "map_Kd", "newmtl", "d",
    "Tr", "Ke", "illum", "\"", "{", "}", "[", "]", ",", "null", "true", "-1", "1e38", "nan", "#", "\\"};
// 32-bit values for binary headers (sizes, offsets, counts), written in either byte order.
const std::vector<uint32_t> kInts = {0, 1, 2, 255, 256, 0x7fff, 0x8000, 0xffff, 0x10000, 0x4000000,
                                     0x7fffffff, 0x80000000, 0xfffffffe, 0xffffffff};

bool is_separator(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ',' || c == '[' || c == ']' || c == '{' ||
         c == '}' || c == ':' || c == '"' || c == '/';
}
bool is_number_char(char c) { return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'; }

// [begin, end) of every token (a run of non-separators); `numeric` keeps only numbers.
std::vector<std::pair<size_t, size_t>> tokens(const std::string& s, bool numeric) {
  std::vector<std::pair<size_t, size_t>> out;
  for (size_t i = 0; i < s.size();) {
    if (is_separator(s[i])) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < s.size() && !is_separator(s[j])) ++j;
    bool number = std::all_of(s.begin() + i, s.begin() + j, is_number_char) &&
                  std::any_of(s.begin() + i, s.begin() + j, [](char c) { return c >= '0' && c <= '9'; });
    if (!numeric || number) out.push_back({i, j});
    i = j;
  }
  return out;
}

// Start offsets of the lines of `s`.
std::vector<size_t> line_starts(const std::string& s) {
  std::vector<size_t> starts = {0};
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\n' && i + 1 < s.size()) starts.push_back(i + 1);
  }
  return starts;
}

// One mutation of `s`, described in `log`. Text files get token- and line-level mutations as
// well as byte-level ones; binary files (images) byte-level ones and 32-bit header values.
void mutate_once(std::string& s, bool text, Rng& rng, std::string& log) {
  const int kinds = text ? 10 : 7;
  switch (rng.below(kinds)) {
    case 0: {  // flip a bit
      if (s.empty()) break;
      size_t at = rng.below(s.size());
      int bit = static_cast<int>(rng.below(8));
      s[at] = static_cast<char>(s[at] ^ (1 << bit));
      log += " flip@" + std::to_string(at) + "." + std::to_string(bit);
      break;
    }
    case 1: {  // set a byte
      if (s.empty()) break;
      static const char kBytes[] = {'\0', '\xff', '\n', '\r', ' ', '-', '.', 'e', '/', '\\', '#', '"', '\x80'};
      size_t at = rng.below(s.size());
      s[at] = kBytes[rng.below(sizeof kBytes)];
      log += " byte@" + std::to_string(at);
      break;
    }
    case 2: {  // delete a range
      if (s.empty()) break;
      size_t at = rng.below(s.size()), n = 1 + rng.below(std::min<size_t>(s.size() - at, 64));
      s.erase(at, n);
      log += " delete@" + std::to_string(at) + "+" + std::to_string(n);
      break;
    }
    case 3: {  // copy a range elsewhere, sometimes many times (long lines, repeated sections)
      if (s.empty()) break;
      size_t from = rng.below(s.size()), n = 1 + rng.below(std::min<size_t>(s.size() - from, 256));
      size_t to = rng.below(s.size() + 1), times = rng.below(4) == 0 ? 1 + rng.below(2000) : 1;
      std::string piece = s.substr(from, n), block;
      for (size_t k = 0; k < times; ++k) block += piece;
      s.insert(to, block);
      log += " copy@" + std::to_string(from) + "+" + std::to_string(n) + "x" + std::to_string(times) + "->" + std::to_string(to);
      break;
    }
    case 4: {  // truncate
      size_t at = rng.below(s.size() + 1);
      s.resize(at);
      log += " truncate@" + std::to_string(at);
      break;
    }
    case 5: {  // a 32-bit value at a random offset, or in the first 64 bytes (image headers)
      if (s.size() < 4) break;
      size_t limit = rng.below(2) == 0 ? std::min<size_t>(s.size() - 3, 64) : s.size() - 3;
      size_t at = rng.below(limit);
      uint32_t v = rng.pick(kInts);
      bool big = rng.below(2) == 0;
      for (int k = 0; k < 4; ++k) s[at + k] = static_cast<char>(big ? v >> (24 - 8 * k) : v >> (8 * k));
      log += " int32@" + std::to_string(at) + "=" + std::to_string(v) + (big ? "be" : "le");
      break;
    }
    case 6: {  // random bytes
      size_t at = rng.below(s.size() + 1), n = 1 + rng.below(16);
      std::string junk;
      for (size_t k = 0; k < n; ++k) junk += static_cast<char>(rng.next());
      s.insert(at, junk);
      log += " junk@" + std::to_string(at) + "+" + std::to_string(n);
      break;
    }
    case 7: {  // a number replaced by an awkward one
      auto t = tokens(s, true);
      if (t.empty()) break;
      auto [a, b] = rng.pick(t);
      const std::string& v = rng.pick(kNumbers);
      s.replace(a, b - a, v);
      log += " number@" + std::to_string(a) + "=" + v;
      break;
    }
    case 8: {  // a word replaced
      auto t = tokens(s, false);
      if (t.empty()) break;
      auto [a, b] = rng.pick(t);
      size_t w = rng.below(kWords.size());
      s.replace(a, b - a, kWords[w]);
      log += " word@" + std::to_string(a) + "=#" + std::to_string(w);
      break;
    }
    case 9: {  // a line duplicated, deleted or moved
      std::vector<size_t> starts = line_starts(s);
      size_t k = rng.below(starts.size());
      size_t a = starts[k], b = k + 1 < starts.size() ? starts[k + 1] : s.size();
      std::string line = s.substr(a, b - a);
      if (!line.empty() && line.back() != '\n') line += '\n';
      size_t how = rng.below(3);
      if (how != 1) s.erase(a, b - a);
      if (how != 0) {
        std::vector<size_t> now = line_starts(s);
        s.insert(std::min(s.size(), now[rng.below(now.size())]), line);
      }
      log += std::string(" line") + (how == 0 ? "-del@" : how == 1 ? "-dup@" : "-move@") + std::to_string(a);
      break;
    }
  }
}

struct Target {
  std::string scene;  // relative to the scenes folder
  std::string file;   // the input mutated, relative to the scenes folder
};

struct Corpus {
  std::vector<std::string> files;  // every input of every scene, relative
  std::vector<Target> targets;
};

// The example scenes (every scene.json under scenes/) that load as they are, and their inputs.
// Inputs over kMaxInputBytes are left unmutated and scenes whose inputs exceed it in total are left
// out: every mutant would spend its time re-reading megabytes that did not change (sky-mesh).
constexpr uintmax_t kMaxInputBytes = uintmax_t(1) << 20;
Corpus example_corpus(const fs::path& root) {
  Corpus corpus;
  std::set<std::string> files;
  std::vector<fs::path> scenes;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file() && e.path().filename() == "scene.json") scenes.push_back(e.path());
  }
  std::sort(scenes.begin(), scenes.end());  // the corpus, hence each seed's mutants, in a fixed order
  for (const fs::path& scene : scenes) {
    std::vector<std::string> inputs;
    try {
      pt::LoadOptions options;
      options.default_lighting = false;
      inputs = pt::read_scene(scene.string(), options).inputs;
    } catch (const std::exception& e) {
      MESSAGE("left out (does not load as it is): " << std::string(e.what()));
      continue;
    }
    inputs.push_back(scene.string());
    std::set<std::string> relative;
    uintmax_t total = 0;
    for (const std::string& in : inputs) {
      relative.insert(fs::relative(fs::canonical(in), fs::canonical(root)).string());
      total += fs::file_size(in);
    }
    std::string name = fs::relative(scene, root).string();
    if (total > kMaxInputBytes) {
      MESSAGE("left out (inputs of " << total << " bytes): " << name);
      continue;
    }
    for (const std::string& r : relative) {
      files.insert(r);
      corpus.targets.push_back({name, r});
    }
  }
  corpus.files.assign(files.begin(), files.end());
  return corpus;
}

bool is_text(const std::string& file) {
  std::string ext = fs::path(file).extension().string();
  return ext == ".obj" || ext == ".mtl" || ext == ".json" || ext == ".gltf";
}

// What a run printed must be one-line messages: no terminal control characters (escape sequences
// from the input), no line beyond the cap of core/util/error.h (plus the prefix and file name).
std::string unprintable(const std::string& text) {
  size_t line = 0;
  for (char c : text) {
    unsigned char u = static_cast<unsigned char>(c);
    if (c == '\n') {
      line = 0;
      continue;
    }
    if ((u < 0x20 && c != '\t') || u == 0x7f) return "a control character " + std::to_string(u);
    if (++line > 8192) return "a line longer than 8192 bytes";
  }
  return "";
}

const char* const kSanitizerMarks[] = {"AddressSanitizer", "LeakSanitizer", "UndefinedBehaviorSanitizer",
                                       "runtime error:", "MemorySanitizer", "ThreadSanitizer"};

}  // namespace

// Size-keeping mutations of binary data (a bit, a byte, a 32-bit value in either byte order).
void mutate_in_place(std::string& s, Rng& rng, std::string& log) {
  if (s.empty()) return;
  size_t at = rng.below(s.size());
  switch (rng.below(3)) {
    case 0:
      s[at] = static_cast<char>(s[at] ^ (1 << rng.below(8)));
      log += " flip@" + std::to_string(at);
      break;
    case 1:
      s[at] = static_cast<char>(rng.next());
      log += " byte@" + std::to_string(at);
      break;
    default: {
      if (s.size() < 4) break;
      at = rng.below(s.size() - 3);
      uint32_t v = rng.pick(kInts);
      bool big = rng.below(2) == 0;
      for (int k = 0; k < 4; ++k) s[at + k] = static_cast<char>(v >> (8 * (big ? 3 - k : k)));
      log += " u32@" + std::to_string(at) + "=" + std::to_string(v) + (big ? "be" : "le");
    }
  }
}

std::string base64_decode(const std::string& in) {
  std::string out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : in) {
    int v = c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52
            : c == '+' ? 62 : c == '/' ? 63 : -1;
    if (v < 0) break;
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((acc >> bits) & 0xff);
    }
  }
  return out;
}

// Half the mutants of a glTF, GLB or PLY file change the part a whole-file mutation seldom
// reaches intact: the bytes inside a .gltf's base64 buffer (decoded, changed in place and
// re-encoded, so the declared byteLength still holds and the mutant gets to the accessors), a
// GLB's JSON chunk as text (the chunk's and the file's lengths then put right, so the mutant gets
// past the GLB header checks) and a PLY's header as text (the body left as it is).
void mutate_file(const std::string& file, std::string& s, Rng& rng, std::string& log) {
  const std::string ext = fs::path(file).extension().string();
  const size_t n = 1 + rng.below(3);
  const bool structured = (ext == ".gltf" || ext == ".glb" || ext == ".ply") && rng.below(2) == 0;
  if (structured && ext == ".gltf") {
    std::vector<size_t> uris;
    for (size_t at = s.find(";base64,"); at != std::string::npos; at = s.find(";base64,", at + 1)) uris.push_back(at + 8);
    if (!uris.empty()) {
      size_t begin = rng.pick(uris), end = s.find('"', begin);
      if (end == std::string::npos) end = s.size();
      std::string bytes = base64_decode(s.substr(begin, end - begin));
      log += " base64@" + std::to_string(begin) + ":";
      for (size_t k = 0; k < n; ++k) mutate_in_place(bytes, rng, log);
      s.replace(begin, end - begin, GltfText::base64(bytes));
      return;
    }
  } else if (structured && ext == ".glb" && s.size() >= 20) {
    uint32_t length;
    std::memcpy(&length, s.data() + 12, 4);
    if (length <= s.size() - 20) {
      std::string json = s.substr(20, length), rest = s.substr(20 + length);
      log += " glb-json:";
      for (size_t k = 0; k < n; ++k) mutate_once(json, true, rng, log);
      while (json.size() % 4) json += ' ';
      uint32_t json_length = static_cast<uint32_t>(json.size()), total = static_cast<uint32_t>(20 + json.size() + rest.size());
      std::string head = s.substr(0, 20);
      std::memcpy(head.data() + 8, &total, 4);
      std::memcpy(head.data() + 12, &json_length, 4);
      s = head + json + rest;
      return;
    }
  } else if (structured && ext == ".ply") {
    size_t end = s.find("end_header");
    if (end != std::string::npos) {
      std::string header = s.substr(0, end);
      log += " ply-header:";
      for (size_t k = 0; k < n; ++k) mutate_once(header, true, rng, log);
      s = header + s.substr(end);
      return;
    }
  }
  const bool text = is_text(file) || (ext == ".ply" && s.rfind("format ascii", 64) != std::string::npos);
  for (size_t k = 0; k < n; ++k) mutate_once(s, text, rng, log);
}

TEST_CASE("mutated example scenes: no crash, hang, sanitizer report, unescaped output or leftover file") {
  const uint64_t seed = env_number("PT_FUZZ_SEED", 11);
  const uint64_t first = env_number("PT_FUZZ_FIRST", 0);
  const uint64_t count = env_number("PT_FUZZ_COUNT", PT_FUZZ_DEFAULT_COUNT);
  const char* keep = std::getenv("PT_FUZZ_KEEP");
#ifdef PT_SANITIZED
  const double timeout_s = 180;  // ASan and UBSan slow pt down by about 3x
#else
  const double timeout_s = 60;
#endif
  // A sanitizer report ends the run with its own exit code, so that it cannot pass for pt's 2.
  // intercept_tls_get_addr=0: GCC 12's sanitizer runtime takes some dynamic-TLS blocks of glibc >=
  // 2.25 for glibc 2.19's layout (a block that happens to start 16 bytes into a page), reads a bogus
  // range from the two words before it, and LeakSanitizer's tracer dies scanning it at exit
  // (google/sanitizers#1322; fixed in GCC 14 / LLVM 17). pt's dlopened image module has such
  // blocks. Without the interceptor, leaks are still found; only dynamic TLS is not a root.
  ::setenv("ASAN_OPTIONS",
           "exitcode=86:detect_leaks=1:abort_on_error=0:allocator_may_return_null=1:"
           "intercept_tls_get_addr=0",
           0);
  ::setenv("UBSAN_OPTIONS", "exitcode=87:print_stacktrace=1:halt_on_error=1", 0);
  // Leaks inside libraries, each one explained in the file (tests/lsan.supp).
  std::string lsan = "exitcode=88:suppressions=" + std::string(PT_SOURCE_DIR) + "/tests/lsan.supp";
  ::setenv("LSAN_OPTIONS", lsan.c_str(), 0);

  const fs::path root = fs::path(PT_SOURCE_DIR) / "scenes";
  Corpus corpus = example_corpus(root);
  REQUIRE(corpus.targets.size() >= 20);
  if (const char* only = std::getenv("PT_FUZZ_ONLY")) {
    // Appended, not "," + ...: GCC 12 warns falsely (-Wrestrict) on that form (as in error.h).
    std::string kinds(1, ',');
    kinds += only;
    kinds += ',';
    std::erase_if(corpus.targets, [&](const Target& t) {
      std::string kind(1, ',');
      kind += fs::path(t.file).extension().string();
      kind += ',';
      return kinds.find(kind) == std::string::npos;
    });
    REQUIRE_MESSAGE(!corpus.targets.empty(), "PT_FUZZ_ONLY=" << only << " matches no input of the example scenes");
  }
  TempDir dir("pt-fuzz");
  const fs::path work = dir.path / "scenes", out_dir = dir.path / "out";
  std::map<std::string, std::string> originals;
  for (const std::string& f : corpus.files) {
    fs::create_directories((work / f).parent_path());
    fs::copy_file(root / f, work / f);
    originals[f] = read_file(root / f);
  }
  fs::create_directories(out_dir);
  auto tree = [&] {
    std::set<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(work)) names.insert(fs::relative(e.path(), work).string());
    return names;
  };
  const std::set<std::string> files_before = tree();

  size_t exits[3] = {0, 0, 0};  // render: 0, 2, other
  std::map<std::string, size_t> per_kind;
  auto start = std::chrono::steady_clock::now();
  for (uint64_t i = first; i < first + count; ++i) {
    Rng rng{seed * 0x100000001b3ull ^ (i + 1) * 0x9e3779b97f4a7c15ull};
    const Target& t = corpus.targets[rng.below(corpus.targets.size())];
    std::string bytes = originals[t.file], log;
    mutate_file(t.file, bytes, rng, log);
    std::ofstream(work / t.file, std::ios::binary | std::ios::trunc) << bytes;
    const std::string ext = rng.below(2) == 0 ? ".png" : ".exr";
    const fs::path image = out_dir / ("out" + ext);
    const std::string scene = (work / t.scene).string();
    const std::string repro = "PT_FUZZ_SEED=" + std::to_string(seed) + " PT_FUZZ_FIRST=" + std::to_string(i) +
                              " PT_FUZZ_COUNT=1 (mutant " + std::to_string(i) + ": " + t.file + log + ")";
    CAPTURE(repro);
    ++per_kind[fs::path(t.file).extension().string()];

    // Both at once: two cores, and they only read the scene.
    pid_t info = start_program(PT_BINARY, {"info", scene}, dir.path / "info.err", dir.path / "info.out");
    pid_t render = start_program(PT_BINARY,
                                 {"render", scene, "--res", "24x16", "--spp", "2", "--threads", "1", "-q", "-o", image.string()},
                                 dir.path / "render.err", dir.path / "render.out");
    Outcome oi = finish(info, dir.path / "info.err", timeout_s, dir.path / "info.out");
    Outcome orr = finish(render, dir.path / "render.err", timeout_s, dir.path / "render.out");
    bool ok = true;
    for (const auto& [what, o] : {std::pair<const char*, const Outcome*>{"info", &oi}, {"render", &orr}}) {
      CAPTURE(what);
      CAPTURE(o->err);
      ok = ok && o->exited && (o->code == 0 || o->code == 2);
      CHECK(o->exited);
      CHECK((o->code == 0 || o->code == 2));
      for (const char* mark : kSanitizerMarks) {
        bool clean = o->err.find(mark) == std::string::npos;
        ok = ok && clean;
        CHECK_MESSAGE(clean, "sanitizer report: " << mark);
      }
      std::string bad = unprintable(o->err) + unprintable(o->out);
      ok = ok && bad.empty();
      CHECK_MESSAGE(bad.empty(), "printed " << bad);
    }
    exits[orr.code == 0 ? 0 : orr.code == 2 ? 1 : 2]++;
    std::vector<std::string> left = listing(out_dir);
    if (orr.code == 0) {
      bool readable = false;
      try {
        pt::Image img = pt::read_image(image.string());
        readable = img.width == 24 && img.height == 16;
      } catch (const std::exception& e) {
        MESSAGE("the image does not read back: " << std::string(e.what()));
      }
      ok = ok && readable && left.size() == 1;
      CHECK(readable);
      CHECK(left == std::vector<std::string>{"out" + ext});
    } else {
      ok = ok && left.empty();
      CHECK_MESSAGE(left.empty(), "a failed render left files in its output folder");
    }
    bool same_tree = tree() == files_before;
    ok = ok && same_tree;
    CHECK_MESSAGE(same_tree, "files appeared in or vanished from the scene folders");
    if (!ok && keep) {
      fs::path kept = fs::path(keep) / ("seed" + std::to_string(seed) + "-mutant" + std::to_string(i));
      fs::create_directories(kept);
      fs::copy(work, kept, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
      MESSAGE("kept in " << kept.string());
    }
    for (const std::string& n : left) fs::remove(out_dir / n);
    std::ofstream(work / t.file, std::ios::binary | std::ios::trunc) << originals[t.file];
  }
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string kinds;
  for (const auto& [k, n] : per_kind) kinds += " " + k + ":" + std::to_string(n);
  MESSAGE("seed " << seed << ", mutants " << first << ".." << first + count - 1 << " of " << corpus.targets.size()
                  << " (scene, input) pairs:" << kinds << "; render exit 0: " << exits[0] << ", exit 2: " << exits[1]
                  << ", other: " << exits[2] << "; " << seconds << " s");
}
