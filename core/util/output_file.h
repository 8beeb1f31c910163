// Output files that are never half-written and never replace what they must not. The bytes go to a
// temporary file in the target's folder (anonymous, via O_TMPFILE, where the filesystem allows it,
// so even SIGKILL leaves nothing behind); every write, the fsync and the close are checked (a full
// disk, EFBIG under `ulimit -f`, EIO), and only a complete file is renamed over the target. On any
// failure the previous file is intact and the temporary is gone.
#pragma once
#include <string>
#include <string_view>

namespace pt {

// What pt may replace: nothing, or a regular file (a symbolic link is followed to one). Throws
// pt::Error naming `path` when its folder is missing or refuses new files, or when a folder,
// device, FIFO or socket is at `path`. Returns the path to write: `path` with symbolic links
// resolved, so that the link, not the file it points to, survives.
std::string check_output_path(const std::string& path);

class OutputFile {
 public:
  // check_output_path, removes this host's temporaries left in that folder by dead pt processes,
  // opens the temporary. Throws pt::Error.
  explicit OutputFile(const std::string& path);
  ~OutputFile();  // without commit(): the temporary is removed, the target untouched
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Throws pt::Error naming the target on any failure (buffered; errors may also surface in commit).
  void write(std::string_view bytes);
  // Flushes, fsyncs, closes and renames the temporary over the target. Throws pt::Error.
  void commit();

  const std::string& path() const { return target_; }

 private:
  void flush();
  [[noreturn]] void fail(const std::string& what, int err);
  void discard();

  std::string shown_;       // as given, for messages
  std::string target_;      // symbolic links resolved
  std::string dir_;
  std::string named_temp_;  // the temporary's name, once it has one (always, without O_TMPFILE)
  int dir_fd_ = -1;
  int fd_ = -1;
  std::string buffer_;
};

// OutputFile in one call.
void write_file(const std::string& path, std::string_view bytes);

// The name this process gives its temporary for `target` (".<name>.<host>-<pid>.pt-tmp" beside
// it), and whether `file_name` is such a temporary of a process on this host that no longer runs.
std::string temporary_name(const std::string& target_file_name);
bool is_stale_temporary(const std::string& file_name);

}  // namespace pt
