#include "core/util/output_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>

#include "core/util/error.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

constexpr size_t kBufferBytes = size_t(1) << 20;
constexpr const char* kTempSuffix = ".pt-tmp";

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0 || buf[0] == '\0') return "localhost";
  std::string host = buf;
  for (char& c : host) {
    if (c == '/') c = '_';
  }
  return host;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

struct Resolved {
  std::string target;     // symbolic links resolved
  std::string dir;        // its folder ("." for a bare name)
  std::string file_name;  // its last component
  bool exists = false;
  mode_t mode = 0;
};

// The checks of check_output_path, without creating anything.
Resolved resolve_output(const std::string& path) {
  if (path.empty()) throw Error("the output path is empty");
  Resolved r;
  r.target = path;
  struct stat st;
  if (::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) {
    std::error_code ec;
    fs::path real = fs::canonical(path, ec);
    if (ec) throw Error(path, "is a symbolic link that leads nowhere (" + ec.message() + ")");
    r.target = real.string();
  }
  fs::path target(r.target);
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..") {
    throw Error(path, "is a folder; name the output file");
  }
  r.file_name = target.filename().string();
  r.dir = target.parent_path().empty() ? "." : target.parent_path().string();
  struct stat dst;
  if (::stat(r.dir.c_str(), &dst) != 0 || !S_ISDIR(dst.st_mode)) throw Error(path, "the output folder does not exist");
  if (::stat(r.target.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw Error(path, "is a folder");
    if (!S_ISREG(st.st_mode)) {
      throw Error(path, "is not a regular file (a device, FIFO or socket); pt replaces only regular files");
    }
    r.exists = true;
    r.mode = st.st_mode & 07777;
  } else if (errno != ENOENT) {
    throw Error(path, std::string("cannot use as output: ") + std::strerror(errno));
  }
  return r;
}

// Removes this host's temporaries of processes that no longer run (left by SIGKILL or a power cut
// while a named temporary existed). Best effort: a folder we cannot list is simply not cleaned.
void remove_stale_temporaries(const std::string& dir, int dir_fd) {
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  while (dirent* e = ::readdir(d)) {
    if (is_stale_temporary(e->d_name)) ::unlinkat(dir_fd, e->d_name, 0);
  }
  ::closedir(d);
}

}  // namespace

std::string temporary_name(const std::string& target_file_name) {
  // Leave room for the host and pid within NAME_MAX (255).
  std::string name(1, '.');
  name += target_file_name.substr(0, 100);
  name += '.';
  name += host_name();
  name += '-';
  name += std::to_string(::getpid());
  name += kTempSuffix;
  return name;
}

bool is_stale_temporary(const std::string& name) {
  if (name.empty() || name[0] != '.' || !ends_with(name, kTempSuffix)) return false;
  std::string rest = name.substr(0, name.size() - std::strlen(kTempSuffix));
  size_t dash = rest.rfind('-');
  if (dash == std::string::npos || dash + 1 == rest.size() || rest.size() - dash > 11) return false;
  long pid = 0;
  for (size_t i = dash + 1; i < rest.size(); ++i) {
    if (rest[i] < '0' || rest[i] > '9') return false;
    pid = pid * 10 + (rest[i] - '0');
  }
  if (pid <= 0 || pid > INT_MAX) return false;
  std::string host_part(1, '.');  // appended, not "." + ...: GCC 12 warns falsely (-Wrestrict) on that
  host_part += host_name();
  if (!ends_with(rest.substr(0, dash), host_part)) return false;
  if (static_cast<pid_t>(pid) == ::getpid()) return false;
  return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

std::string check_output_path(const std::string& path) {
  // Find out now, not after an hour of rendering, whether the folder takes new files: open a
  // temporary and drop it (access(2) would say yes to root even where creation fails, e.g. /proc).
  OutputFile probe(path);
  return probe.path();
}

OutputFile::OutputFile(const std::string& path) {
  Resolved r = resolve_output(path);
  shown_ = path;
  target_ = r.target;
  dir_ = r.dir;
  dir_fd_ = ::open(dir_.c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd_ < 0) throw Error(path, std::string("cannot open the output folder: ") + std::strerror(errno));
  remove_stale_temporaries(dir_, dir_fd_);
  fd_ = ::openat(dir_fd_, ".", O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  if (fd_ < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
    // This filesystem has no anonymous files: a named temporary, cleaned up as above if we die.
    named_temp_ = temporary_name(r.file_name);
    ::unlinkat(dir_fd_, named_temp_.c_str(), 0);  // our own name: only an earlier process with our pid left it
    fd_ = ::openat(dir_fd_, named_temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ < 0) named_temp_.clear();
  }
  if (fd_ < 0) {
    int err = errno;
    ::close(dir_fd_);
    dir_fd_ = -1;
    throw Error(path, std::string("cannot write to the output folder: ") + std::strerror(err));
  }
  if (r.exists) ::fchmod(fd_, r.mode);  // a replaced file keeps its permissions
}

OutputFile::~OutputFile() { discard(); }

void OutputFile::discard() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!named_temp_.empty() && dir_fd_ >= 0) ::unlinkat(dir_fd_, named_temp_.c_str(), 0);
  named_temp_.clear();
  if (dir_fd_ >= 0) ::close(dir_fd_);
  dir_fd_ = -1;
}

void OutputFile::fail(const std::string& what, int err) {
  discard();
  throw Error(shown_, what + " (" + std::strerror(err) + "); nothing was replaced");
}

void OutputFile::write(std::string_view bytes) {
  if (fd_ < 0) throw Error(shown_, "write after the file was closed");
  buffer_.append(bytes);
  if (buffer_.size() >= kBufferBytes) flush();
}

void OutputFile::flush() {
  const char* p = buffer_.data();
  size_t left = buffer_.size();
  while (left > 0) {
    ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot write", errno);  // ENOSPC, EFBIG (SIGXFSZ is ignored), EIO, EDQUOT ...
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  buffer_.clear();
}

void OutputFile::commit() {
  if (fd_ < 0) throw Error(shown_, "commit after the file was closed");
  flush();
  // Delayed allocation and network filesystems may report a full disk only here.
  if (::fsync(fd_) != 0 && errno != EINVAL) fail("cannot write", errno);
  if (named_temp_.empty()) {
    // Give the anonymous file a name beside the target, then rename that over it: linkat cannot
    // replace an existing file. /proc/self/fd works for everyone; AT_EMPTY_PATH needs privileges.
    std::string name = temporary_name(fs::path(target_).filename().string());
    ::unlinkat(dir_fd_, name.c_str(), 0);
    std::string self = "/proc/self/fd/" + std::to_string(fd_);
    if (::linkat(AT_FDCWD, self.c_str(), dir_fd_, name.c_str(), AT_SYMLINK_FOLLOW) != 0 &&
        ::linkat(fd_, "", dir_fd_, name.c_str(), AT_EMPTY_PATH) != 0) {
      fail("cannot give the finished file a name", errno);
    }
    named_temp_ = name;
  }
  int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail("cannot write", errno);
  std::string file_name = fs::path(target_).filename().string();
  if (::renameat(dir_fd_, named_temp_.c_str(), dir_fd_, file_name.c_str()) != 0) {
    fail("cannot rename the finished file into place", errno);
  }
  named_temp_.clear();
  discard();
}

void write_file(const std::string& path, std::string_view bytes) {
  OutputFile out(path);
  out.write(bytes);
  out.commit();
}

}  // namespace pt
