// Validation of OBJ and MTL text before tinyobjloader parses it (obj_validate.cpp says why).
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace pt {

struct ObjScan {
  std::vector<std::string> mtllibs;    // as written after `mtllib`
  std::set<std::string> unsupported;   // statements we do not model
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
  float ka_max = 0;              // largest Ka component
  bool has_ke = false;           // a Ke line with a non-zero component
};
using MtlScan = std::map<std::string, MtlFacts>;  // by material name, as tinyobjloader names it

// Throws pt::Error with file:line on anything tinyobjloader would misread.
ObjScan validate_obj(const std::string& path);
// Validates an MTL file's numbers and adds the keys we do not model to `unsupported`; fills
// `facts` (when given) for each material the file defines (the first definition of a name wins).
void validate_mtl(const std::string& path, std::set<std::string>& unsupported, MtlScan* facts = nullptr);

}  // namespace pt
