// Validation of OBJ and MTL text before tinyobjloader parses it (obj_validate.cpp says why).
#pragma once
#include <set>
#include <string>
#include <vector>

namespace pt {

struct ObjScan {
  std::vector<std::string> mtllibs;    // as written after `mtllib`
  std::set<std::string> unsupported;   // statements we do not model
};

// Throws pt::Error with file:line on anything tinyobjloader would misread.
ObjScan validate_obj(const std::string& path);
// Validates an MTL file's numbers and adds the keys we do not model to `unsupported`.
void validate_mtl(const std::string& path, std::set<std::string>& unsupported);

}  // namespace pt
