// KHR_draco_mesh_compression: primitives whose attributes and indices are a Draco-compressed
// buffer view, decoded through Debian's libdraco-dev.
#pragma once
#include "core/scene/gltf_file.h"

namespace pt {

// Decodes every Draco-compressed primitive of a validated file and points its accessors at the
// decoded values (new buffers, FLOAT attributes and UNSIGNED_INT indices), so that the rest of the
// loader reads them as any other accessor. Throws pt::Error naming the file and a JSON pointer
// where the extension or its data is malformed, or disagrees with the accessors.
void decode_draco(GltfFile& file);

}  // namespace pt
