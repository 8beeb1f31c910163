// What pt reads must be a regular file: a FIFO, /dev/zero or /dev/urandom named as a scene, a
// material library or a texture would be read forever. These checks use stat(2), which never
// blocks on a FIFO, and turn every filesystem failure (a symbolic link loop, a permission) into
// the usual one-line pt::Error naming the file.
#pragma once
#include <cstdint>
#include <string>

namespace pt {

enum class FileKind { kMissing, kRegular, kFolder, kOther };

// What is at `path`, following symbolic links. Throws pt::Error naming `path` for anything but
// "exists" or "does not exist" (a symbolic link loop, a component that is not a folder, EACCES).
FileKind file_kind(const std::string& path);

// Throws pt::Error naming `path` unless it is a regular file ("no such file", "is a folder",
// "is not a regular file (a FIFO, device or socket)"). `what` names the role with its article,
// e.g. "an image".
void require_regular_file(const std::string& path, const char* what);

// The whole of a regular file, refusing one larger than `max_bytes` (named in the error).
std::string read_whole_file(const std::string& path, uint64_t max_bytes, const char* what);

}  // namespace pt
