// The PLY parser. The header is read line by line; before anything is allocated from its counts,
// the body is checked to be large enough to hold them (a 100-byte file cannot make pt reserve
// memory for 4 billion vertices). Each element is then read by its properties in order; what pt
// does not use is skipped by its type, so any element and property may appear.
#include "core/scene/ply_reader.h"

#include <bit>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "core/image/image.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/text.h"

namespace pt {
namespace {

enum class Format { kAscii, kLittle, kBig };

struct Type {
  const char* name;
  const char* alias;
  int size;
  bool is_int;
  bool is_signed;
};
constexpr Type kTypes[] = {{"char", "int8", 1, true, true},      {"uchar", "uint8", 1, true, false},
                           {"short", "int16", 2, true, true},    {"ushort", "uint16", 2, true, false},
                           {"int", "int32", 4, true, true},      {"uint", "uint32", 4, true, false},
                           {"float", "float32", 4, false, true}, {"double", "float64", 8, false, true}};

const Type* find_type(const std::string& name) {
  for (const Type& t : kTypes) {
    if (name == t.name || name == t.alias) return &t;
  }
  return nullptr;
}

// What pt takes from a property.
enum class Role { kNone, kX, kY, kZ, kNx, kNy, kNz, kU, kV, kRed, kGreen, kBlue, kIndices };

struct Property {
  std::string name;
  const Type* type = nullptr;
  const Type* count_type = nullptr;  // lists only
  Role role = Role::kNone;
  int line = 0;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  int line = 0;
};

// One line of the text from `pos` (which moves past it), without its line ending.
std::string_view next_line(std::string_view text, size_t& pos) {
  size_t end = text.find('\n', pos);
  size_t stop = end == std::string_view::npos ? text.size() : end;
  std::string_view line = text.substr(pos, stop - pos);
  pos = end == std::string_view::npos ? text.size() : end + 1;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

Role vertex_role(const std::string& n) {
  if (n == "x") return Role::kX;
  if (n == "y") return Role::kY;
  if (n == "z") return Role::kZ;
  if (n == "nx") return Role::kNx;
  if (n == "ny") return Role::kNy;
  if (n == "nz") return Role::kNz;
  if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") return Role::kU;
  if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") return Role::kV;
  if (n == "red" || n == "diffuse_red") return Role::kRed;
  if (n == "green" || n == "diffuse_green") return Role::kGreen;
  if (n == "blue" || n == "diffuse_blue") return Role::kBlue;
  return Role::kNone;
}

// a * b, or nullopt when it overflows 64 bits.
std::optional<uint64_t> multiply(uint64_t a, uint64_t b) {
  uint64_t r;
  if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
  return r;
}

struct Header {
  Format format = Format::kAscii;
  std::string format_name;
  std::vector<Element> elements;
  size_t body = 0;  // byte offset of the body
  int lines = 0;    // header lines, so body lines can be numbered as in the file
};

Header parse_header(const std::string& path, std::string_view bytes) {
  Header h;
  size_t pos = 0;
  int line_no = 0;
  bool have_format = false;
  auto fail = [&](const std::string& message) -> Error { return Error(path, line_no, message); };
  constexpr size_t kMaxHeaderBytes = size_t(1) << 20;
  while (true) {
    if (pos >= bytes.size()) throw Error(path, "the PLY header has no 'end_header' line");
    if (pos > kMaxHeaderBytes) throw Error(path, "no 'end_header' in the first 1 MiB: not a PLY header");
    std::string_view raw = next_line(bytes, pos);
    ++line_no;
    if (raw.find('\0') != std::string_view::npos) throw fail("binary data (a NUL byte) in the PLY header");
    if (line_no == 1) {
      if (raw != "ply") throw Error(path, "not a PLY file (the first line is not 'ply')");
      continue;
    }
    std::vector<std::string> t = split_blanks(raw);
    if (t.empty()) continue;
    const std::string& key = t[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") break;
    if (key == "format") {
      if (t.size() != 3) throw fail("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (t[1] == "ascii") h.format = Format::kAscii;
      else if (t[1] == "binary_little_endian") h.format = Format::kLittle;
      else if (t[1] == "binary_big_endian") h.format = Format::kBig;
      else throw fail("unknown PLY format " + quote(t[1]));
      if (t[2] != "1.0") throw fail("PLY version " + quote(t[2]) + " (pt reads 1.0)");
      h.format_name = t[1];
      have_format = true;
    } else if (key == "element") {
      if (t.size() != 3) throw fail("expected 'element NAME COUNT'");
      const char* s = t[2].c_str();
      char* end = nullptr;
      errno = 0;
      unsigned long long count = std::strtoull(s, &end, 10);
      if (t[2][0] == '-' || end == s || *end != '\0' || errno == ERANGE || count > UINT32_MAX) {
        throw fail("element " + quote(t[1]) + " count " + quote(t[2]) + " is not an integer from 0 to " +
                   std::to_string(UINT32_MAX));
      }
      // One vertex list and one face list: their indices and per-vertex arrays are one numbering.
      for (const Element& e : h.elements) {
        if (e.name == t[1] && (t[1] == "vertex" || t[1] == "face" || t[1] == "tristrips")) {
          throw fail("a second element " + quote(t[1]) + " (the first is on line " + std::to_string(e.line) + ")");
        }
      }
      h.elements.push_back({t[1], count, {}, line_no});
    } else if (key == "property") {
      if (h.elements.empty()) throw fail("'property' before any 'element'");
      Element& e = h.elements.back();
      Property p;
      p.line = line_no;
      if (t.size() >= 2 && t[1] == "list") {
        if (t.size() != 5) throw fail("expected 'property list COUNT_TYPE ITEM_TYPE NAME'");
        p.count_type = find_type(t[2]);
        p.type = find_type(t[3]);
        if (!p.count_type || !p.type) throw fail("unknown PLY type " + quote(p.count_type ? t[3] : t[2]));
        if (!p.count_type->is_int) throw fail("a list's count type must be an integer type, not " + quote(t[2]));
        p.name = t[4];
      } else {
        if (t.size() != 3) throw fail("expected 'property TYPE NAME'");
        p.type = find_type(t[1]);
        if (!p.type) throw fail("unknown PLY type " + quote(t[1]));
        p.name = t[2];
      }
      if (e.name == "vertex") p.role = vertex_role(p.name);
      if ((e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index")) ||
          (e.name == "tristrips" && p.name == "vertex_indices")) {
        p.role = Role::kIndices;
      }
      if (p.role == Role::kIndices && (!p.count_type || !p.type->is_int)) {
        throw fail(quote(p.name) + " of " + quote(e.name) + " must be a list of integers");
      }
      if (p.role != Role::kNone && p.role != Role::kIndices && p.count_type) {
        throw fail(quote(p.name) + " of 'vertex' must be a single value, not a list");
      }
      e.properties.push_back(p);
    } else {
      throw fail("unknown PLY header line " + quote(key));
    }
  }
  if (!have_format) throw Error(path, "the PLY header has no 'format' line");
  h.body = pos;
  h.lines = line_no;
  return h;
}

// The body, read value by value. Binary: from a byte offset, swapping bytes where the file's order
// is not the machine's. ASCII: one element per line, its values separated by blanks.
class BinaryBody {
 public:
  BinaryBody(const std::string& path, std::string_view bytes, size_t pos, bool big)
      : path_(path), bytes_(bytes), pos_(pos), swap_(big != (std::endian::native == std::endian::big)) {}
  void begin(const Element& e, uint64_t index) {
    element_ = &e;
    index_ = index;
  }
  void end() {}
  double value(const Type& t) {
    if (bytes_.size() - pos_ < static_cast<size_t>(t.size)) throw error("the file ends inside this element (truncated)");
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, t.size);
    pos_ += t.size;
    if (swap_) {
      for (int i = 0; i < t.size / 2; ++i) std::swap(b[i], b[t.size - 1 - i]);
    }
    return decode(t, b);
  }
  void skip(const Type& t, uint64_t n) {
    auto bytes = multiply(n, static_cast<uint64_t>(t.size));
    if (!bytes || *bytes > bytes_.size() - pos_) throw error("a list of " + std::to_string(n) + " values runs past the end of the file");
    pos_ += *bytes;
  }
  size_t remaining() const { return bytes_.size() - pos_; }
  bool fits(const Type& t, uint64_t n) const {
    auto bytes = multiply(n, static_cast<uint64_t>(t.size));
    return bytes && *bytes <= remaining();
  }
  Error error(const std::string& message) const {
    return Error(path_, "element " + quote(element_->name) + " " + std::to_string(index_) + ": " + message);
  }

 private:
  static double decode(const Type& t, const unsigned char* b) {
    switch (t.size) {
      case 1: return t.is_signed ? double(static_cast<int8_t>(b[0])) : double(b[0]);
      case 2: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        return t.is_signed ? double(static_cast<int16_t>(v)) : double(v);
      }
      case 4: {
        if (!t.is_int) {
          float f;
          std::memcpy(&f, b, 4);
          return f;
        }
        uint32_t v;
        std::memcpy(&v, b, 4);
        return t.is_signed ? double(static_cast<int32_t>(v)) : double(v);
      }
      default: {
        double d;
        std::memcpy(&d, b, 8);
        return d;
      }
    }
  }
  const std::string& path_;
  std::string_view bytes_;
  size_t pos_;
  bool swap_;
  const Element* element_ = nullptr;
  uint64_t index_ = 0;
};

class AsciiBody {
 public:
  AsciiBody(const std::string& path, std::string_view bytes, size_t pos, int lines)
      : path_(path), bytes_(bytes), pos_(pos), line_(lines) {}
  void begin(const Element& e, uint64_t index) {
    element_ = &e;
    index_ = index;
    tokens_.clear();
    next_ = 0;
    while (tokens_.empty()) {
      if (pos_ >= bytes_.size()) {
        throw Error(path_, "the file ends before element " + quote(e.name) + " " + std::to_string(index) + " of " +
                               std::to_string(e.count) + " (truncated)");
      }
      std::string_view raw = next_line(bytes_, pos_);
      ++line_;
      if (raw.find('\0') != std::string_view::npos) throw error("binary data (a NUL byte) in an ASCII PLY file");
      tokens_ = split_blanks(raw);
    }
  }
  void end() {
    if (next_ < tokens_.size()) {
      throw error(std::to_string(tokens_.size()) + " values on the line, but " + quote(element_->name) + " has " +
                  std::to_string(next_) + " here");
    }
  }
  double value(const Type& t) {
    if (next_ >= tokens_.size()) throw error("too few values on the line for element " + quote(element_->name));
    const std::string& s = tokens_[next_++];
    const char* begin = s.c_str();
    char* end = nullptr;
    errno = 0;
    double v;
    if (t.is_int) {
      long long i = std::strtoll(begin, &end, 10);
      if (end == begin || *end != '\0' || errno == ERANGE) throw error(quote(s) + " is not an integer");
      double lo = t.is_signed ? -std::ldexp(1.0, 8 * t.size - 1) : 0.0;
      double hi = std::ldexp(1.0, 8 * t.size - (t.is_signed ? 1 : 0)) - 1;
      if (double(i) < lo || double(i) > hi) throw error(quote(s) + " does not fit the type " + quote(t.name));
      v = double(i);
    } else {
      v = std::strtod(begin, &end);
      if (end == begin || *end != '\0') throw error(quote(s) + " is not a number");
    }
    return v;
  }
  void skip(const Type& t, uint64_t n) {
    if (n > tokens_.size() - next_) throw error("a list of " + std::to_string(n) + " values, but the line has fewer");
    for (uint64_t i = 0; i < n; ++i) value(t);
  }
  bool fits(const Type&, uint64_t n) const { return n <= tokens_.size() - next_; }
  Error error(const std::string& message) const { return Error(path_, line_, message); }

 private:
  const std::string& path_;
  std::string_view bytes_;
  size_t pos_;
  int line_;
  const Element* element_ = nullptr;
  uint64_t index_ = 0;
  std::vector<std::string> tokens_;
  size_t next_ = 0;
};

// The fewest bytes the elements can take: a check against the file's size before any count is
// trusted with an allocation.
void check_counts(const std::string& path, const Header& h, uint64_t body_bytes) {
  uint64_t total = 0;
  for (const Element& e : h.elements) {
    if (e.count > 0 && e.properties.empty()) {
      throw Error(path, e.line, "element " + quote(e.name) + " has no properties");
    }
    uint64_t per = 0;
    for (const Property& p : e.properties) {
      // ASCII: at least one digit and one blank per value; binary: the value or the list's count.
      per += h.format == Format::kAscii ? 2 : static_cast<uint64_t>(p.count_type ? p.count_type->size : p.type->size);
    }
    auto need = multiply(e.count, per);
    if (!need || (total += *need) > body_bytes + 1) {
      throw Error(path, e.line, "the header promises " + std::to_string(e.count) + " " + quote(e.name) +
                                    " elements, more than the file's " + std::to_string(body_bytes) +
                                    " body bytes can hold (truncated or a wrong count)");
    }
  }
}

template <class Body>
void read_body(const std::string& path, const Header& h, Body& body, PlyMesh& out) {
  uint64_t vertices = 0;
  for (const Element& e : h.elements) {
    if (e.name == "vertex") vertices = e.count;
  }
  std::vector<int64_t> list;
  for (const Element& e : h.elements) {
    bool is_vertex = e.name == "vertex";
    bool has[int(Role::kIndices) + 1] = {};
    for (const Property& p : e.properties) {
      has[int(p.role)] = true;
      if (p.role == Role::kNone) out.ignored.insert(e.name + "." + p.name);
    }
    bool normals = has[int(Role::kNx)] && has[int(Role::kNy)] && has[int(Role::kNz)];
    bool uvs = has[int(Role::kU)] && has[int(Role::kV)];
    bool colors = has[int(Role::kRed)] && has[int(Role::kGreen)] && has[int(Role::kBlue)];
    // Part of a set (a lone `red`, nx without ny and nz) is read and not used: said, not dropped silently.
    for (const Property& p : e.properties) {
      if (!is_vertex) break;
      const Role r = p.role;
      const bool part_of_normal = r == Role::kNx || r == Role::kNy || r == Role::kNz;
      const bool part_of_uv = r == Role::kU || r == Role::kV;
      const bool part_of_colour = r == Role::kRed || r == Role::kGreen || r == Role::kBlue;
      if (part_of_normal && !normals) out.ignored.insert(e.name + "." + p.name + " (a normal needs nx, ny and nz)");
      if (part_of_uv && !uvs) out.ignored.insert(e.name + "." + p.name + " (a uv needs both coordinates)");
      if (part_of_colour && !colors) out.ignored.insert(e.name + "." + p.name + " (a colour needs red, green and blue)");
    }
    if (is_vertex) {
      if (!has[int(Role::kX)] || !has[int(Role::kY)] || !has[int(Role::kZ)]) {
        throw Error(path, e.line, "element 'vertex' needs properties x, y and z");
      }
      out.positions.resize(e.count);
      if (normals) out.normals.resize(e.count);
      if (uvs) out.uvs.resize(e.count);
      if (colors) out.colors.resize(e.count);
    }
    bool strip = e.name == "tristrips";
    bool faces = e.name == "face";
    if ((faces || strip) && !has[int(Role::kIndices)]) {
      throw Error(path, e.line, "element " + quote(e.name) + " has no vertex_indices list");
    }
    if (!is_vertex && !faces && !strip) out.ignored.insert(e.name);
    for (uint64_t i = 0; i < e.count; ++i) {
      body.begin(e, i);
      float values[int(Role::kIndices)] = {};
      for (const Property& p : e.properties) {
        if (!p.count_type) {
          double v = body.value(*p.type);
          if (p.role == Role::kNone) continue;
          if (!std::isfinite(v) || std::abs(v) > FLT_MAX) {
            throw body.error("vertex property " + quote(p.name) + " is not a finite number");
          }
          float f = static_cast<float>(v);
          if (p.role == Role::kRed || p.role == Role::kGreen || p.role == Role::kBlue) {
            // Integer colours are display values, sRGB-encoded as 8- and 16-bit textures are;
            // float colours are taken as linear reflectances.
            if (p.type->is_int) {
              f = srgb_decode(static_cast<float>(v / (std::ldexp(1.0, 8 * p.type->size) - 1)));
            }
            if (!(f >= 0.0f && f <= 1.0f)) throw body.error("colour " + quote(p.name) + " outside [0, 1]");
          }
          values[int(p.role)] = f;
          continue;
        }
        double n = body.value(*p.count_type);
        if (n < 0) throw body.error("a list with a negative count");
        if (p.role != Role::kIndices) {
          body.skip(*p.type, static_cast<uint64_t>(n));
          continue;
        }
        if (!body.fits(*p.type, static_cast<uint64_t>(n))) {
          throw body.error("a list of " + std::to_string(static_cast<uint64_t>(n)) + " indices runs past the end of the file");
        }
        list.clear();
        for (uint64_t k = 0; k < static_cast<uint64_t>(n); ++k) {
          double v = body.value(*p.type);
          bool restart = strip && v == -1;
          if (!restart && (v < 0 || v >= static_cast<double>(vertices))) {
            throw body.error("vertex index " + std::to_string(static_cast<int64_t>(v)) + " but the file has " +
                             std::to_string(vertices) + " vertices");
          }
          list.push_back(static_cast<int64_t>(v));
        }
        if (faces) {
          if (list.size() < 3) throw body.error("a face with " + std::to_string(list.size()) + " vertices (at least 3)");
          for (size_t k = 1; k + 1 < list.size(); ++k) {  // a fan: convex polygons come out right
            int64_t a = list[0], b = list[k], c = list[k + 1];
            if (a != b && b != c && a != c) out.triangles.insert(out.triangles.end(), {uint32_t(a), uint32_t(b), uint32_t(c)});
          }
          ++out.faces;
        } else {
          // A strip: every 3 consecutive indices make a triangle, the odd ones turned round to
          // keep the winding; -1 starts a new strip; repeated indices (turns) give no triangle.
          size_t start = 0;
          for (size_t k = 0; k <= list.size(); ++k) {
            if (k < list.size() && list[k] != -1) {
              if (k - start >= 2) {
                int64_t a = list[k - 2], b = list[k - 1], c = list[k];
                if ((k - start) % 2 == 1) std::swap(a, b);
                if (a != b && b != c && a != c) out.triangles.insert(out.triangles.end(), {uint32_t(a), uint32_t(b), uint32_t(c)});
              }
              continue;
            }
            if (k > start) ++out.strips;
            start = k + 1;
          }
        }
      }
      body.end();
      if (is_vertex) {
        out.positions[i] = {values[int(Role::kX)], values[int(Role::kY)], values[int(Role::kZ)]};
        if (normals) out.normals[i] = {values[int(Role::kNx)], values[int(Role::kNy)], values[int(Role::kNz)]};
        if (uvs) out.uvs[i] = {values[int(Role::kU)], values[int(Role::kV)]};
        if (colors) out.colors[i] = {values[int(Role::kRed)], values[int(Role::kGreen)], values[int(Role::kBlue)]};
      }
    }
  }
}

}  // namespace

PlyMesh parse_ply(const std::string& path, std::string_view bytes) {
  Header h = parse_header(path, bytes);
  check_counts(path, h, bytes.size() - h.body);
  bool any_vertex = false;
  for (const Element& e : h.elements) any_vertex = any_vertex || e.name == "vertex";
  if (!any_vertex) throw Error(path, "the PLY file has no 'vertex' element");
  PlyMesh out;
  out.format = h.format_name;
  if (h.format == Format::kAscii) {
    AsciiBody body(path, bytes, h.body, h.lines);
    read_body(path, h, body, out);
  } else {
    BinaryBody body(path, bytes, h.body, h.format == Format::kBig);
    read_body(path, h, body, out);
    if (body.remaining() > 0) {
      out.ignored.insert(std::to_string(body.remaining()) + " bytes after the last element");
    }
  }
  if (out.triangles.empty()) {
    throw Error(path, out.faces + out.strips == 0 ? "the PLY file has no faces (a point cloud?); pt renders surfaces"
                                                  : "the PLY file's faces make no triangle");
  }
  return out;
}

PlyMesh read_ply(const std::string& path) {
  std::string bytes = read_whole_file(path, kMaxPlyBytes, "a PLY file");
  return parse_ply(path, bytes);
}

}  // namespace pt
