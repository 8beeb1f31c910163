#include "core/util/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/util/error.h"

namespace pt {

FileKind file_kind(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return FileKind::kMissing;
    throw Error(path, std::strerror(errno));  // ELOOP: "Too many levels of symbolic links", EACCES, ENOTDIR ...
  }
  if (S_ISREG(st.st_mode)) return FileKind::kRegular;
  if (S_ISDIR(st.st_mode)) return FileKind::kFolder;
  return FileKind::kOther;
}

void require_regular_file(const std::string& path, const char* what) {
  switch (file_kind(path)) {
    case FileKind::kRegular: return;
    case FileKind::kMissing: throw Error(path, "no such file");
    case FileKind::kFolder: throw Error(path, std::string("is a folder, not ") + what);
    case FileKind::kOther:
      throw Error(path, std::string("is not a regular file (a FIFO, device or socket), so pt does not read it as ") + what);
  }
}

std::string read_whole_file(const std::string& path, uint64_t max_bytes, const char* what) {
  require_regular_file(path, what);
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw Error(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {  // replaced between the two looks
    ::close(fd);
    throw Error(path, std::string("is not a regular file, so pt does not read it as ") + what);
  }
  if (static_cast<uint64_t>(st.st_size) > max_bytes) {
    ::close(fd);
    throw Error(path, "is " + std::to_string(st.st_size) + " bytes; pt reads at most " + std::to_string(max_bytes) +
                          " bytes as " + what);
  }
  std::string text(static_cast<size_t>(st.st_size), '\0');
  size_t done = 0;
  while (done < text.size()) {
    ssize_t n = ::read(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int err = errno;
      ::close(fd);
      throw Error(path, std::string("read error: ") + std::strerror(err));
    }
    if (n == 0) break;  // shrank while we read
    done += static_cast<size_t>(n);
  }
  ::close(fd);
  text.resize(done);
  return text;
}

}  // namespace pt
