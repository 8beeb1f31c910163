// The first pass over OBJ and MTL files: Debian's tinyobjloader (2.0.0rc10) reads "nan", "inf"
// and non-numbers as 0 and accepts out-of-range indices, so this pass checks what it would let
// through and reports file:line before tinyobjloader does the real parse. It splits lines (at
// "\n", "\r\n" and a lone "\r") and tokens (at spaces and tabs only) as tinyobjloader does; a
// validator that saw other lines could be talked past (a lone-CR file once smuggled a "nan" by).
#include "core/scene/obj_validate.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "core/scene/input_limits.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/text.h"

namespace pt {
namespace {

// tinyobjloader separates tokens by spaces and tabs only (IS_SPACE); any other byte is part of a
// token, where is_keyword or the number grammar refuses it.
std::vector<std::string> split(const std::string& line) { return split_blanks(line); }

// The decimal numbers both strtod and tinyobjloader's tryParseDouble read the same way:
// [+-] (digits [. digits*] | . digits) [(e|E) [+-] digits]. No hex, "inf" or "nan".
bool is_decimal(const std::string& t) {
  size_t i = 0, n = t.size();
  if (i < n && (t[i] == '+' || t[i] == '-')) ++i;
  size_t int_digits = 0, frac_digits = 0;
  while (i < n && t[i] >= '0' && t[i] <= '9') ++i, ++int_digits;
  if (i < n && t[i] == '.') {
    ++i;
    while (i < n && t[i] >= '0' && t[i] <= '9') ++i, ++frac_digits;
  }
  if (int_digits == 0 && frac_digits == 0) return false;
  if (i < n && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    if (i < n && (t[i] == '+' || t[i] == '-')) ++i;
    size_t exp_digits = 0;
    while (i < n && t[i] >= '0' && t[i] <= '9') ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  return i == n;
}

// Finite as a float, too: geometry is stored in float, and 1e39 would become infinity there.
bool parse_finite(const std::string& token, double& value) {
  if (!is_decimal(token)) return false;
  const char* begin = token.c_str();
  char* end = nullptr;
  value = std::strtod(begin, &end);
  return end != begin && *end == '\0' && std::isfinite(value) && std::abs(value) <= FLT_MAX;
}

// OBJ and MTL keywords are printable ASCII; anything else means the file is not text we can read
// (a binary file without NUL bytes would otherwise pass as a list of unknown statements).
bool is_keyword(const std::string& token) {
  for (unsigned char c : token) {
    if (c < 0x21 || c > 0x7e) return false;
  }
  return true;
}

void require_numbers(const std::vector<std::string>& tokens, size_t min_count, size_t max_count,
                     const std::string& file, int line) {
  size_t n = tokens.size() - 1;
  if (n < min_count || n > max_count) {
    throw Error(file, line, quote(tokens[0]) + " expects " + std::to_string(min_count) +
                                (max_count > min_count ? " to " + std::to_string(max_count) : "") + " numbers, got " +
                                std::to_string(n));
  }
  for (size_t i = 1; i < tokens.size(); ++i) {
    double v;
    if (!parse_finite(tokens[i], v)) {
      throw Error(file, line, quote(tokens[i]) + " in " + quote(tokens[0]) + " is not a finite number");
    }
  }
}

struct IndexCheck {
  long max_positive = 0;
  int line_of_max = 0;
  int first_line = 0;          // first face line using this kind of index
  int line_before_first = 0;   // first negative index reaching before the first element, if deferred
  std::string token_before_first;
};

// Validates one index of a face corner; negative indices are relative to the count so far. With
// `defer`, a negative index reaching before the first element is recorded, not thrown: the caller
// decides at the end (a file with no normals at all gets a warning, not an error).
void check_index(const std::string& token, long count_so_far, IndexCheck& check, const std::string& what,
                 const std::string& file, int line, bool defer = false) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  long value = std::strtol(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE || value > INT_MAX || value < -INT_MAX) {
    throw Error(file, line, "face " + what + " index " + quote(token) + " is not a valid integer");
  }
  if (value == 0) throw Error(file, line, "face " + what + " index 0 (OBJ indices start at 1)");
  if (check.first_line == 0) check.first_line = line;
  if (value < 0 && -value > count_so_far) {
    if (!defer) throw Error(file, line, "face " + what + " index " + quote(token) + " points before the first " + what);
    if (check.line_before_first == 0) {
      check.line_before_first = line;
      check.token_before_first = token;
    }
  }
  if (value > check.max_positive) {
    check.max_positive = value;
    check.line_of_max = line;
  }
}

// Texture coordinate and normal indices: an error when the file has some but not that one; when it
// has none at all, the faces load without them (returns the first line that named one, or 0).
int check_optional_indices(const IndexCheck& check, long count, const std::string& what, const std::string& file) {
  if (count == 0) return check.first_line;
  if (check.line_before_first > 0) {
    throw Error(file, check.line_before_first,
                "face " + what + " index " + quote(check.token_before_first) + " points before the first " + what);
  }
  if (check.max_positive > count) {
    throw Error(file, check.line_of_max, "face " + what + " index " + std::to_string(check.max_positive) +
                                             " but the file has " + std::to_string(count));
  }
  return 0;
}

}  // namespace

LineReader::LineReader(Fill fill, std::string path, const char* kind)
    : fill_(std::move(fill)), path_(std::move(path)), kind_(kind), buffer_(size_t(1) << 16) {}

bool LineReader::refill() {
  if (eof_) return false;
  end_ = fill_(buffer_.data(), buffer_.size());
  pos_ = 0;
  if (end_ == 0) eof_ = true;
  return end_ > 0;
}

bool LineReader::next(std::string& line) {
  line.clear();
  if (pos_ == end_ && !refill()) return false;
  ++line_;
  while (true) {
    if (pos_ == end_ && !refill()) return true;  // the last line has no line ending
    const char* begin = buffer_.data() + pos_;
    size_t n = end_ - pos_;
    // Up to the next byte that ends the line or is refused.
    size_t k = 0;
    while (k < n && begin[k] != '\n' && begin[k] != '\r' && begin[k] != '\0') ++k;
    if (line.size() + k > kMaxLineBytes) {
      throw Error(path_, line_, "a line longer than " + std::to_string(kMaxLineBytes >> 20) + " MiB in " + kind_);
    }
    line.append(begin, k);
    pos_ += k;
    if (k == n) continue;
    char c = buffer_[pos_++];
    if (c == '\0') throw Error(path_, line_, std::string("binary data (a NUL byte) in ") + kind_);
    if (c == '\r') {
      if (pos_ == end_) refill();
      if (pos_ < end_ && buffer_[pos_] == '\n') ++pos_;
    }
    return true;
  }
}

std::vector<std::string> split_mtllib(std::string_view names) {
  // tinyobjloader's SplitString(names, ' ', '\\'): a backslash keeps the next byte as it is.
  std::vector<std::string> out;
  std::string name;
  bool escaping = false;
  for (char c : names) {
    if (escaping) {
      escaping = false;
    } else if (c == '\\') {
      escaping = true;
      continue;
    } else if (c == ' ') {
      if (!name.empty()) out.push_back(name);
      name.clear();
      continue;
    }
    name += c;
  }
  if (!name.empty()) out.push_back(name);
  return out;
}

ObjScan validate_obj(const std::string& path) {
  require_regular_file(path, "an OBJ file");
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw Error(path, std::string("cannot open the file: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  LineReader lines(
      [&](char* buffer, size_t capacity) -> size_t {
        while (true) {
          ssize_t n = ::read(fd, buffer, capacity);
          if (n >= 0) return static_cast<size_t>(n);
          if (errno != EINTR) throw Error(path, std::string("read error: ") + std::strerror(errno));
        }
      },
      path, "a text OBJ file");
  ObjScan scan;
  long nv = 0, nvt = 0, nvn = 0;
  IndexCheck cv, cvt, cvn;
  std::string raw;
  while (lines.next(raw)) {
    const int line = lines.line_number();
    auto tokens = split(raw);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (!is_keyword(tokens[0])) throw Error(path, line, "binary data or an unreadable statement in an OBJ file");
    const std::string& key = tokens[0];
    if (key == "v") {
      require_numbers(tokens, 3, 7, path, line);  // x y z [w] or x y z r g b
      ++nv;
    } else if (key == "vn") {
      require_numbers(tokens, 3, 3, path, line);
      ++nvn;
    } else if (key == "vt") {
      require_numbers(tokens, 1, 3, path, line);
      ++nvt;
    } else if (key == "f") {
      if (tokens.size() < 4) throw Error(path, line, "a face needs at least 3 vertices");
      if (tokens.size() - 1 > kMaxFaceVertices) {
        throw Error(path, line, "a face with " + std::to_string(tokens.size() - 1) + " vertices; pt takes at most " +
                                    std::to_string(kMaxFaceVertices) + " per face (triangulate the model first)");
      }
      for (size_t i = 1; i < tokens.size(); ++i) {
        const std::string& corner = tokens[i];
        size_t s1 = corner.find('/');
        size_t s2 = s1 == std::string::npos ? std::string::npos : corner.find('/', s1 + 1);
        check_index(corner.substr(0, s1), nv, cv, "vertex", path, line);
        if (s1 != std::string::npos) {
          std::string t = corner.substr(s1 + 1, s2 == std::string::npos ? std::string::npos : s2 - s1 - 1);
          if (!t.empty()) check_index(t, nvt, cvt, "texture coordinate", path, line, true);
          if (s2 != std::string::npos) check_index(corner.substr(s2 + 1), nvn, cvn, "normal", path, line, true);
        }
      }
    } else if (key == "mtllib") {
      // tinyobjloader takes the text after "mtllib" and one separator.
      size_t at = raw.find("mtllib") + 7;
      std::vector<std::string> names = split_mtllib(at < raw.size() ? std::string_view(raw).substr(at) : "");
      if (names.empty()) throw Error(path, line, "'mtllib' without a file name");
      scan.mtllib_names.insert(scan.mtllib_names.end(), names.begin(), names.end());
    } else if (key.rfind("usemtl", 0) == 0) {
      // tinyobjloader matches "usemtl" as a prefix and takes the next word as the name.
      std::string name = key.size() > 6 ? key.substr(6) : tokens.size() > 1 ? tokens[1] : "";
      scan.usemtl_lines.emplace(name, line);
    } else if (key == "o" || key == "g" || key == "s") {
    } else {
      scan.unsupported.insert(key);
    }
  }
  if (cv.max_positive > nv) {
    throw Error(path, cv.line_of_max, "face vertex index " + std::to_string(cv.max_positive) + " but the file has " +
                                          std::to_string(nv) + " vertices");
  }
  scan.uvs_missing_line = check_optional_indices(cvt, nvt, "texture coordinate", path);
  scan.normals_missing_line = check_optional_indices(cvn, nvn, "normal", path);
  return scan;
}

// The name tinyobjloader gives a material: what follows "newmtl" and one blank, trailing blanks
// and the line ending removed.
std::string material_name(std::string raw) {
  raw.erase(raw.find_last_not_of(" \t\r\n") + 1);
  size_t at = raw.find_first_not_of(" \t");
  return at == std::string::npos || at + 7 > raw.size() ? std::string() : raw.substr(at + 7);
}

void validate_mtl(const std::string& path, std::string_view text, std::set<std::string>& unsupported, MtlScan* facts) {
  static const std::set<std::string> kColour = {"Kd", "Ks", "Ke", "Ka", "Tf"};
  static const std::set<std::string> kScalar = {"Ns", "Ni", "d", "Tr", "illum", "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor"};
  // The PBR extension's keys (Blender's OBJ exporter with "PBR Extensions"): any of them makes
  // the material a metallic-roughness one (obj_loader.cpp).
  static const std::set<std::string> kPbr = {"Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor", "map_Pr", "map_Pm", "map_Ps"};
  // Ka is read (a Ka far above 1 with no Ke looks like a light the exporter meant) but not
  // modelled: every exporter writes it and no physically based renderer uses it, so it is not
  // listed as unsupported either.
  static const std::set<std::string> kUsed = {"newmtl", "Kd", "Ks", "Ke", "Ka", "Ns", "Ni", "d", "Tr", "illum", "map_Kd", "map_Ke",
                                              "Pr", "Pm", "Pc", "Pcr", "map_Pr", "map_Pm", "norm", "bump", "map_Bump",
                                              "map_bump"};
  size_t offset = 0;
  LineReader lines(
      [&](char* buffer, size_t capacity) {
        size_t n = std::min(capacity, text.size() - offset);
        std::memcpy(buffer, text.data() + offset, n);
        offset += n;
        return n;
      },
      path, "a text MTL file");
  std::string raw;
  bool in_material = false;
  MtlFacts* current = nullptr;
  MtlFacts ignored;  // a repeated name: tinyobjloader keeps the first definition
  while (lines.next(raw)) {
    const int line = lines.line_number();
    auto tokens = split(raw);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    if (!is_keyword(tokens[0])) throw Error(path, line, "binary data or an unreadable statement in an MTL file");
    const std::string& key = tokens[0];
    if (key == "newmtl") {
      // An empty name (Blender 2.6x writes one) is recorded under the name "" in `facts`; the
      // loader renames it, since tinyobjloader would not start a material for it.
      in_material = true;
      if (facts) {
        auto [it, fresh] = facts->try_emplace(material_name(raw));
        current = fresh ? &it->second : &ignored;
        *current = MtlFacts{};
        current->file = path;
        current->line = line;
      }
      continue;
    }
    if (!in_material) throw Error(path, line, quote(key) + " before any 'newmtl'");
    if (kColour.count(key)) {
      if (tokens.size() > 1 && (tokens[1] == "spectral" || tokens[1] == "xyz")) {
        unsupported.insert(key + " " + tokens[1]);
        continue;
      }
      require_numbers(tokens, 1, 3, path, line);
      for (size_t i = 1; i < tokens.size(); ++i) {
        const double v = std::strtod(tokens[i].c_str(), nullptr);
        if (v < 0) throw Error(path, line, "negative value in " + quote(key));
        if (v > kMaxRadiance) throw Error(path, line, quote(key) + " value above " + kMaxRadianceText);
      }
    } else if (kScalar.count(key)) {
      require_numbers(tokens, 1, 1, path, line);
      if (key == "Pr" || key == "Pm" || key == "Pc" || key == "Pcr") {
        float v = std::strtof(tokens[1].c_str(), nullptr);
        if (!(v >= 0.0f && v <= 1.0f)) throw Error(path, line, quote(key) + " must be from 0 to 1");
      }
    } else if (key == "map_Kd" || key == "map_Ke" || key == "map_Pr" || key == "map_Pm") {
      if (tokens.size() < 2) throw Error(path, line, quote(key) + " without a file name");
    }
    if (current && kPbr.count(key)) current->pbr = true;
    if (current && tokens.size() > 1 && kUsed.count(key)) {
      float first = std::strtof(tokens[1].c_str(), nullptr);
      if (key == "d") current->d = first;
      if (key == "Tr") current->tr = first;
      if (key == "map_Kd") current->map_kd_line = line;
      if (key == "map_Ke") current->map_ke_line = line;
      if (key == "map_Pr") current->map_pr_line = line;
      if (key == "map_Pm") current->map_pm_line = line;
      if (key == "Pr") current->pr = first;
      if (key == "Pm") current->pm = first;
      if (key == "Pc") current->pc = first;
      if (key == "Pcr") current->pcr = first;
      if (key == "Ns") current->ns = first;
      if (key == "Ks") current->has_ks = true;
      if (key == "norm") current->norm_line = line;
      if (key == "bump" || key == "map_Bump" || key == "map_bump") current->bump_line = line;
      for (size_t i = 1; i < tokens.size() && (key == "Ka" || key == "Ke"); ++i) {
        float v = std::strtof(tokens[i].c_str(), nullptr);
        if (key == "Ka") current->ka_max = std::max(current->ka_max, v);
        if (key == "Ke" && v > 0) current->has_ke = true;
      }
    }
    if (!kUsed.count(key)) unsupported.insert(key);
  }
}

}  // namespace pt
