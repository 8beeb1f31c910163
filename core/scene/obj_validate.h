// Validation of OBJ and MTL text before tinyobjloader parses it (obj_validate.cpp says why). The
// validator reads lines and tokens exactly as tinyobjloader does, so the two see the same text.
#pragma once
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace pt {

// Bounds on what one line may cost. tinyobjloader triangulates a polygon by ear clipping in time
// quadratic in its vertex count (a 64k-vertex face took 16 s); at 1024 vertices a face costs
// about 1 µs per input byte, within ~100x of ordinary parsing.
constexpr size_t kMaxFaceVertices = 1024;
constexpr size_t kMaxLineBytes = size_t(1) << 20;
constexpr size_t kMaxMtlBytes = size_t(64) << 20;

struct ObjScan {
  std::set<std::string> unsupported;         // statements we do not model
  std::map<std::string, int> usemtl_lines;   // material name -> first line that uses it
  std::vector<std::string> mtllib_names;     // every name on every `mtllib` line, as tinyobjloader splits them
  // Faces that name normals (texture coordinates) in a file that has none, as OpenSubdiv's
  // exports do: the first such line, or 0. The loader ignores those indices and says so once.
  int normals_missing_line = 0;
  int uvs_missing_line = 0;
};

// What material conversion needs that tinyobjloader does not keep: which of `d` and `Tr` the file
// wrote, and where things are, so that warnings can name the MTL line.
struct MtlFacts {
  std::string file;
  int line = 0;                  // of `newmtl`
  std::optional<float> d, tr;    // as written
  int map_kd_line = 0;           // 0: no map_Kd
  int map_ke_line = 0;           // 0: no map_Ke
  int norm_line = 0, bump_line = 0;  // norm; bump or map_Bump
  float ka_max = 0;              // largest Ka component
  bool has_ke = false;           // a Ke line with a non-zero component
  // The PBR extension: any of its keys (Pr, Pm, Ps, Pc, Pcr, aniso, anisor, map_Pr, map_Pm,
  // map_Ps) makes this a metallic-roughness material; tinyobjloader reads an absent Pr as 0.
  bool pbr = false;
  std::optional<float> pr, pm, ns, pc, pcr;
  bool has_ks = false;
  int map_pr_line = 0, map_pm_line = 0;
};
using MtlScan = std::map<std::string, MtlFacts>;  // by material name, as tinyobjloader names it

// Splits text into lines as tinyobjloader's safeGetline does: "\n", "\r\n" and a lone "\r" each
// end a line. A NUL byte (binary data, or the hole of a sparse file) or a line longer than
// kMaxLineBytes is refused as soon as it is seen, so memory stays bounded whatever the file holds.
class LineReader {
 public:
  using Fill = std::function<size_t(char* buffer, size_t capacity)>;  // 0 at the end
  LineReader(Fill fill, std::string path, const char* kind);
  bool next(std::string& line);
  int line_number() const { return line_; }

 private:
  bool refill();
  Fill fill_;
  std::string path_;
  const char* kind_;
  std::vector<char> buffer_;
  size_t pos_ = 0, end_ = 0;
  bool eof_ = false;
  int line_ = 0;
};

// The names on an `mtllib` line (the text after the keyword), split as tinyobjloader splits them:
// at spaces, with backslash escapes, empty names dropped.
std::vector<std::string> split_mtllib(std::string_view names);

// Throws pt::Error with file:line on anything tinyobjloader would misread or take too long on.
ObjScan validate_obj(const std::string& path);
// Validates the text of an MTL file (read from `path`) and adds the keys we do not model to
// `unsupported`; fills `facts` (when given) for each material the file defines (the first
// definition of a name wins).
void validate_mtl(const std::string& path, std::string_view text, std::set<std::string>& unsupported,
                  MtlScan* facts = nullptr);

}  // namespace pt
