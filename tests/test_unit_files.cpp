// Files in and out: OutputFile never replaces what it must not and leaves nothing behind, even when
// its process is killed; inputs must be regular files; messages quote input capped and escaped; the
// OBJ line reader splits lines as tinyobjloader does and stops at binary data.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "core/scene/obj_validate.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/output_file.h"
#include "temp_dir.h"

using namespace pt;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::set<std::string> names_in(const fs::path& folder) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(folder)) names.insert(e.path().filename().string());
  return names;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A pid that no process has: a child that has exited and been reaped.
pid_t dead_pid() {
  pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

std::string temp_name_for(const std::string& target, pid_t pid) {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  return "." + target + "." + host + "-" + std::to_string(pid) + ".pt-tmp";
}

std::vector<std::string> lines_of(const std::string& text) {
  size_t offset = 0;
  LineReader reader(
      [&](char* buffer, size_t capacity) {
        // Three bytes at a time, so line endings fall across refills too.
        size_t n = std::min<size_t>({capacity, 3, text.size() - offset});
        std::copy(text.data() + offset, text.data() + offset + n, buffer);
        offset += n;
        return n;
      },
      "test.obj", "a text OBJ file");
  std::vector<std::string> lines;
  for (std::string line; reader.next(line);) lines.push_back(line);
  return lines;
}

}  // namespace

TEST_CASE("OutputFile: the target changes only on commit, and only a regular file is replaced") {
  TempDir dir("pt-files");
  fs::path target = dir.path / "out.txt";
  write_file(target.string(), "first");
  CHECK(slurp(target) == "first");
  ::chmod(target.c_str(), 0640);
  {
    OutputFile out(target.string());
    out.write("second");
    CHECK(slurp(target) == "first");  // nothing visible before commit
  }                                   // destroyed without commit
  CHECK(slurp(target) == "first");
  CHECK(names_in(dir.path) == std::set<std::string>{"out.txt"});
  write_file(target.string(), std::string(3 << 20, 'x'));  // several buffer flushes
  CHECK(slurp(target).size() == size_t(3) << 20);
  struct stat st;
  REQUIRE(::stat(target.c_str(), &st) == 0);
  CHECK((st.st_mode & 07777) == 0640);  // a replaced file keeps its permissions
  CHECK(names_in(dir.path) == std::set<std::string>{"out.txt"});

  // A symbolic link to a regular file: the file it points to is replaced, the link stays a link.
  fs::create_symlink("out.txt", dir.path / "link.txt");
  write_file((dir.path / "link.txt").string(), "through the link");
  CHECK(fs::is_symlink(dir.path / "link.txt"));
  CHECK(slurp(target) == "through the link");

  // What must never be replaced.
  fs::create_directories(dir.path / "folder");
  CHECK(error_of([&] { write_file((dir.path / "folder").string(), "x"); }).find("is a folder") != std::string::npos);
  REQUIRE(::mkfifo((dir.path / "fifo").c_str(), 0644) == 0);
  CHECK(error_of([&] { write_file((dir.path / "fifo").string(), "x"); }).find("not a regular file") != std::string::npos);
  CHECK(fs::is_fifo(dir.path / "fifo"));
  fs::create_symlink("/dev/null", dir.path / "null.png");
  CHECK(error_of([&] { write_file((dir.path / "null.png").string(), "x"); }).find("not a regular file") != std::string::npos);
  CHECK(fs::is_character_file("/dev/null"));
  fs::create_symlink("nowhere", dir.path / "dangling.png");
  CHECK(error_of([&] { write_file((dir.path / "dangling.png").string(), "x"); }).find("leads nowhere") != std::string::npos);
  if (::geteuid() == 0) {
    // As root, a device node: /dev/null's numbers, in our own folder.
    fs::path node = dir.path / "device.png";
    REQUIRE(::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0);
    CHECK(error_of([&] { write_file(node.string(), "x"); }).find("not a regular file") != std::string::npos);
    CHECK(fs::is_character_file(node));
  }
  CHECK(error_of([&] { check_output_path((dir.path / "no" / "out.png").string()); }).find("folder does not exist") !=
        std::string::npos);
  CHECK(error_of([&] { check_output_path("/proc/pt-test.png"); }).find("cannot write") != std::string::npos);
}

TEST_CASE("OutputFile: a process killed mid-write leaves nothing that the next write does not remove") {
  TempDir dir("pt-files");
  int ready[2];
  REQUIRE(::pipe(ready) == 0);
  pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    OutputFile out((dir.path / "killed.png").string());
    out.write(std::string(4 << 20, 'x'));  // past the buffer: bytes are in the temporary
    char c = 1;
    if (::write(ready[1], &c, 1) != 1) ::_exit(1);
    ::pause();
    ::_exit(0);
  }
  char c = 0;
  REQUIRE(::read(ready[0], &c, 1) == 1);
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  ::close(ready[0]);
  ::close(ready[1]);
  // With O_TMPFILE the killed write never had a name; without it, the next write in the folder
  // removes this host's temporaries of dead processes.
  write_file((dir.path / "next.png").string(), "x");
  CHECK(names_in(dir.path) == std::set<std::string>{"next.png"});

  // Only the dead: a temporary of a live process (ours) and one of another host stay.
  std::string dead = temp_name_for("old.png", dead_pid());
  std::string alive = temp_name_for("old.png", ::getpid());
  std::string other_host = ".old.png.some-other-host-" + std::to_string(dead_pid()) + ".pt-tmp";
  for (const std::string& name : {dead, alive, other_host}) std::ofstream(dir.path / name) << "partial";
  CHECK(is_stale_temporary(dead));
  CHECK_FALSE(is_stale_temporary(alive));
  CHECK_FALSE(is_stale_temporary(other_host));
  CHECK_FALSE(is_stale_temporary("old.png"));
  write_file((dir.path / "next.png").string(), "y");
  CHECK(names_in(dir.path) == std::set<std::string>{"next.png", alive, other_host});
}

TEST_CASE("inputs: only regular files, and filesystem failures as one-line errors") {
  TempDir dir("pt-files");
  std::string file = dir.write("a.obj", "v 0 0 0\n");
  CHECK(file_kind(file) == FileKind::kRegular);
  CHECK(file_kind((dir.path / "none").string()) == FileKind::kMissing);
  CHECK(file_kind(dir.path.string()) == FileKind::kFolder);
  CHECK(file_kind("/dev/zero") == FileKind::kOther);
  CHECK(error_of([] { require_regular_file("/dev/urandom", "an image"); }).find("not a regular file") != std::string::npos);
  fs::create_symlink("loop2", dir.path / "loop1");
  fs::create_symlink("loop1", dir.path / "loop2");
  std::string loop = error_of([&] { file_kind((dir.path / "loop1").string()); });
  CHECK(loop.find("loop1") != std::string::npos);
  CHECK(loop.find("symbolic links") != std::string::npos);
  CHECK(read_whole_file(file, 100, "a test") == "v 0 0 0\n");
  CHECK(error_of([&] { read_whole_file(file, 4, "a test"); }).find("at most 4 bytes") != std::string::npos);
}

TEST_CASE("messages: quoted input is cut, every printed line is escaped") {
  CHECK(quote("abc") == "'abc'");
  std::string long_token(1 << 20, '7');
  std::string q = quote(long_token);
  CHECK(q.size() < 100);
  CHECK(q.find("1048576 bytes") != std::string::npos);
  CHECK(printable("a\nb\tc\r") == "a\\nb\\tc\\r");
  CHECK(printable("\x1b[31mred") == "\\x1b[31mred");  // no escape sequence reaches the terminal
  CHECK(printable("back\\slash") == "back\\\\slash");
  CHECK(printable("caf\xc3\xa9 \xe2\x82\xac") == "caf\xc3\xa9 \xe2\x82\xac");  // UTF-8 stays
  CHECK(printable("\xc2\x9b" "1m") == "\\xc2\\x9b1m");  // C1 CSI, encoded, is escaped
  CHECK(printable("\xff\xfe") == "\\xff\\xfe");          // not UTF-8
  CHECK(printable("\xc0\xaf") == "\\xc0\\xaf");          // overlong
  CHECK(printable(std::string(10000, 'x')).size() < kMaxMessageBytes + 40);
}

TEST_CASE("the OBJ line reader splits lines as tinyobjloader does and refuses binary data") {
  CHECK(lines_of("a\nb\r\nc\rd") == std::vector<std::string>{"a", "b", "c", "d"});
  CHECK(lines_of("a\r\r\nb\n\n") == std::vector<std::string>{"a", "", "b", ""});
  CHECK(lines_of("") == std::vector<std::string>{});
  std::string nul = error_of([] { lines_of(std::string("v 0 0 0\nv 1\0 0 0\n", 17)); });
  CHECK(nul.find("test.obj:2:") != std::string::npos);
  std::string huge = error_of([] { lines_of("# short\n" + std::string(kMaxLineBytes + 1, 'x')); });
  CHECK(huge.find("test.obj:2:") != std::string::npos);
  CHECK(split_mtllib("a.mtl b.mtl") == std::vector<std::string>{"a.mtl", "b.mtl"});
  CHECK(split_mtllib("my\\ materials.mtl  b.mtl ") == std::vector<std::string>{"my materials.mtl", "b.mtl"});
}
