#include "feeddrive/output/folder.hpp"

#include <signal.h>

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (_GNU_SOURCE)
#include <sys/stat.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "feeddrive/output/gnuplot.hpp"

namespace feeddrive::output {
namespace fs = std::filesystem;

namespace {

// Room the temporary siblings need beyond the name: "." + NAME + ".partial-PID-N".
constexpr std::size_t kSiblingExtra = 40;
constexpr std::size_t kMaxName = NAME_MAX - kSiblingExtra;
constexpr std::size_t kMaxPath = PATH_MAX - kSiblingExtra;
constexpr std::uintmax_t kMaxMarkerBytes = 1 << 16;  // the header and the list of a few dozen files

[[noreturn]] void refuse(const std::string& option, const std::string& value, const std::string& why) {
  throw std::invalid_argument(option + " " + shown(value) + ": " + why);
}

std::string error_text(int err) { return std::strerror(err); }

// A fresh sibling of `target` named ".NAME.<kind>-PID-N" that does not exist yet.
fs::path unused_sibling(const fs::path& target, const std::string& kind) {
  for (int n = 0;; ++n) {
    const fs::path p = target.parent_path() / ("." + target.filename().string() + "." + kind + "-" +
                                               std::to_string(::getpid()) + "-" + std::to_string(n));
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(p, ec))) return p;
  }
}

// Can this process create entries in folder `dir`? access() first (it knows read-only file
// systems, and permission bits for anyone but root), then a real probe: a folder made and removed.
int writable(const fs::path& dir) {
  if (::access(dir.c_str(), W_OK | X_OK) != 0) return errno;
  const fs::path probe = unused_sibling(dir / "probe", "feeddrive-probe");
  if (::mkdir(probe.c_str(), 0700) != 0) return errno;
  ::rmdir(probe.c_str());
  return 0;
}

bool empty_folder(const fs::path& dir) {
  std::error_code ec;
  const bool e = fs::is_empty(dir, ec);
  return !ec && e;
}

// fsync of one file or folder (opened read-only); errno on failure, 0 on success.
int sync_path(const fs::path& p, bool folder) {
  const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC | (folder ? O_DIRECTORY : 0));
  if (fd < 0) return errno;
  const int rc = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return rc;
}

// Durability: every regular file of `dir` and `dir` itself reach the disk before the folder is
// renamed into place, so that a power cut after the rename cannot leave DIR holding empty or
// short files (the rename is then made durable by syncing the parent, sync_parent).
void sync_folder(const fs::path& dir, const std::string& what) {
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const bool folder = it->is_directory(ec);
    if (!folder && !it->is_regular_file(ec)) continue;
    if (const int e = sync_path(it->path(), folder))
      throw std::runtime_error(what + "cannot flush " + it->path().string() + " to disk: " + error_text(e));
  }
  if (ec) throw std::runtime_error(what + "cannot list " + dir.string() + ": " + ec.message());
  if (const int e = sync_path(dir, true))
    throw std::runtime_error(what + "cannot flush " + dir.string() + " to disk: " + error_text(e));
}

// After a rename: the parent's entry is durable too. Best effort (the results are in place).
void sync_parent(const fs::path& target) { (void)sync_path(target.parent_path(), true); }

bool exchange(const fs::path& a, const fs::path& b, int& err) {
  if (::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0) return true;
  err = errno;
  return false;
}

// The names the marker of `dir` lists ("file: NAME" lines after the three header lines), and
// whether it lists any: a marker written before the list existed, or by a run still going, has
// none.
bool listed_files(const fs::path& dir, std::vector<std::string>& names) {
  std::ifstream in(dir / kMarkerFile, std::ios::binary);
  std::string line;
  bool listed = false;
  for (int n = 0; std::getline(in, line); ++n) {
    if (n < 3) continue;
    if (line == "files:") listed = true;
    else if (listed && line.rfind("file: ", 0) == 0) names.push_back(line.substr(6));
  }
  return listed;
}

}  // namespace

std::string foreign_entry(const fs::path& dir) {
  std::vector<std::string> listed;
  if (!is_feeddrive_output(dir) || !listed_files(dir, listed)) return "";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name != kMarkerFile && std::find(listed.begin(), listed.end(), name) == listed.end()) return name;
  }
  return "";
}

std::string marker_text(const std::string& tool) {
  return "feeddrive-output\nformat: " + std::to_string(kFormatVersion) + "\ntool: " + tool + "\n";
}

std::string output_tool(const fs::path& dir) {
  if (!is_feeddrive_output(dir)) return "";
  std::ifstream in(dir / kMarkerFile, std::ios::binary);
  std::string line;
  std::getline(in, line);
  std::getline(in, line);
  std::getline(in, line);
  return line.substr(6);  // "tool: NAME", checked by is_feeddrive_output
}

void write_file_atomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = unused_sibling(path, "tmp");
  {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    f.close();
    if (!f) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(path.string() + ": write failed");
    }
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(path.string() + ": cannot rename into place: " + error_text(e));
  }
}

bool is_feeddrive_output(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec))) return false;
  const fs::path marker = dir / kMarkerFile;
  const auto st = fs::symlink_status(marker, ec);
  if (ec || !fs::is_regular_file(st) || fs::file_size(marker, ec) > kMaxMarkerBytes || ec) return false;
  std::ifstream in(marker, std::ios::binary);
  std::string magic, format, tool;
  if (!std::getline(in, magic) || !std::getline(in, format) || !std::getline(in, tool)) return false;
  if (magic != "feeddrive-output" || format.rfind("format: ", 0) != 0 || tool.rfind("tool: ", 0) != 0) return false;
  const std::string version = format.substr(8);
  return !version.empty() && version.find_first_not_of("0123456789") == std::string::npos && tool.size() > 6;
}

std::string shown(const std::string& value) {
  if (value.empty()) return "\"\"";
  std::string s = value;
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return s;
}

fs::path normalise(const std::string& out, const std::string& option) {
  if (out.empty()) refuse(option, out, "empty path; name the output folder, e.g. out/run");
  fs::path p = fs::path(out).lexically_normal();
  while (!p.empty() && !p.has_filename() && p.has_relative_path()) p = p.parent_path();  // "prev/" -> "prev"
  if (p.empty() || !p.has_filename() || p.filename() == "." || p.filename() == "..")
    refuse(
        option, out,
        "names no folder of its own (the current folder, a parent or the root); name the output folder, e.g. out/run");
  return p;
}

fs::path check_output_dir(const std::string& out, const std::string& option) {
  const fs::path p = normalise(out, option);
  const std::size_t name = p.filename().string().size();
  if (name > kMaxName)
    refuse(
        option, out,
        "the folder name is too long (" + std::to_string(name) + " bytes; at most " + std::to_string(kMaxName) + ")");
  std::error_code ec;
  const fs::path abs = fs::absolute(p, ec);
  if (ec) refuse(option, out, "cannot resolve the path: " + ec.message());
  if (abs.string().size() > kMaxPath)
    refuse(option, out,
           "the path is too long (" + std::to_string(abs.string().size()) + " bytes; at most " +
               std::to_string(kMaxPath) + ")");

  const auto st = fs::symlink_status(abs, ec);
  if (!ec && fs::exists(st)) {
    if (fs::is_symlink(st)) refuse(option, out, "is a symbolic link; name the folder itself");
    if (!fs::is_directory(st)) refuse(option, out, "exists and is not a folder");
    std::error_code ec2;
    const bool empty = fs::is_empty(abs, ec2);
    if (ec2) refuse(option, out, "cannot read the folder: " + ec2.message());
    if (!empty && !is_feeddrive_output(abs))
      refuse(option, out,
             std::string("folder exists, is not empty and is not a feeddrive output (no ") + kMarkerFile +
                 " marker); refusing to replace it");
    if (const std::string f = foreign_entry(abs); !f.empty())
      refuse(option, out,
             "holds '" + shown(f) + "', which feeddrive did not write (its " + kMarkerFile +
                 " lists what it wrote); move it out or choose another folder");
  } else if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
    refuse(option, out, "cannot be checked: " + ec.message());
  }

  // The nearest folder that exists above it: every name on the way is created later, so none
  // may be a file, and the folder must take new entries.
  fs::path up = abs.parent_path();
  for (;;) {
    const auto s = fs::status(up, ec);
    if (!ec && fs::exists(s)) {
      if (!fs::is_directory(s)) refuse(option, out, up.string() + " is not a folder");
      break;
    }
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
      refuse(option, out, "cannot check " + up.string() + ": " + ec.message());
    if (!up.has_relative_path()) refuse(option, out, "no existing folder above it");
    up = up.parent_path();
  }
  if (const int err = writable(up); err != 0)
    refuse(option, out, "cannot write in " + up.string() + ": " + error_text(err));
  return p;
}

void check_outside(const std::string& file, const std::string& file_option, const std::string& out,
                   const std::string& option) {
  if (file.empty()) return;
  std::error_code ec;
  const fs::path f = fs::absolute(fs::path(file), ec).lexically_normal();
  const fs::path d = fs::absolute(normalise(out, option), ec).lexically_normal();
  if (ec) return;
  // f lies in d if d's components are a prefix of f's
  auto fi = f.begin();
  for (auto di = d.begin(); di != d.end(); ++di, ++fi)
    if (fi == f.end() || *fi != *di) return;
  if (fi == f.end())
    refuse(file_option, file, "is the output folder " + option + " " + shown(out) + " itself; name a file next to it");
  refuse(file_option, file,
         "lies inside " + option + " " + shown(out) +
             ", which is replaced when the run ends (the file would be lost); put it next to the folder");
}

void check_output_file(const std::string& file, const std::string& option, const std::string& magic) {
  if (file.empty()) return;
  struct stat st {};
  if (::stat(file.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) refuse(option, file, "is a folder; name a file");
    if (S_ISFIFO(st.st_mode)) refuse(option, file, "is a FIFO (a writer would block on it); name a regular file");
    if (!S_ISREG(st.st_mode)) refuse(option, file, "is a device or socket, not a regular file");
    if (::access(file.c_str(), W_OK) != 0)
      refuse(option, file, "exists and is not writable (" + error_text(errno) + ")");
    // Opened for writing, without truncating it: what root's access() does not see (a read-only
    // mount, a pseudo file system) shows here.
    // /proc and /sys files pass every check above for root and take no log.
    struct statfs fs {};
    if (::statfs(file.c_str(), &fs) == 0 &&
        (fs.f_type == 0x9fa0 /* PROC_SUPER_MAGIC */ || fs.f_type == 0x62656572 /* SYSFS_MAGIC */))
      refuse(option, file, "is a kernel pseudo file (/proc, /sys), not a file to write a log to");
    const int fd = ::open(file.c_str(), O_RDWR | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) refuse(option, file, "cannot be opened for writing (" + error_text(errno) + ")");
    std::string head(magic.size(), '\0');
    const ssize_t got = magic.empty() || st.st_size == 0 ? 0 : ::read(fd, head.data(), head.size());
    ::close(fd);
    if (!magic.empty() && st.st_size > 0 && (got != static_cast<ssize_t>(magic.size()) || head != magic))
      refuse(option, file,
             "exists and is not a file this option writes (" + std::to_string(st.st_size) +
                 " bytes); it is not replaced: name a new file, or remove it first");
    return;
  }
  if (errno != ENOENT) refuse(option, file, "cannot be examined (" + error_text(errno) + ")");
  const fs::path parent = fs::path(file).parent_path().empty() ? fs::path(".") : fs::path(file).parent_path();
  if (::stat(parent.c_str(), &st) != 0) refuse(option, file, "its folder " + parent.string() + " does not exist");
  if (!S_ISDIR(st.st_mode)) refuse(option, file, parent.string() + " is not a folder");
  if (::access(parent.c_str(), W_OK | X_OK) != 0)
    refuse(option, file, "its folder " + parent.string() + " is not writable (" + error_text(errno) + ")");
  // Created and removed again: /proc, /sys or a read-only mount pass the checks above for root but
  // take no new file.
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) refuse(option, file, "cannot be created (" + error_text(errno) + ")");
  ::close(fd);
  ::unlink(file.c_str());
}

void replace_folder(const fs::path& fresh, const fs::path& target) {
  sync_folder(fresh, target.string() + ": ");
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(target, ec))) {
    if (::rename(fresh.c_str(), target.c_str()) != 0)
      throw std::runtime_error(target.string() + ": cannot rename " + fresh.string() +
                               " into place: " + error_text(errno));
  } else {
    int err = 0;
    if (exchange(fresh, target, err)) {
      fs::remove_all(fresh, ec);  // now the old folder
    } else if (err == EINVAL || err == ENOSYS || err == EOPNOTSUPP) {
      fs::remove_all(target, ec);
      if (::rename(fresh.c_str(), target.c_str()) != 0)
        throw std::runtime_error(target.string() + ": cannot rename " + fresh.string() +
                                 " into place: " + error_text(errno));
    } else {
      throw std::runtime_error(target.string() + ": cannot swap " + fresh.string() + " into place: " + error_text(err));
    }
  }
  sync_parent(target);
}

bool remove_output(const fs::path& dir) noexcept {
  try {
    std::error_code ec;
    if (!fs::is_directory(fs::symlink_status(dir, ec))) return false;
    if (!is_feeddrive_output(dir) && !empty_folder(dir)) return false;
    fs::remove_all(dir, ec);
    return !ec;
  } catch (...) {
    return false;
  }
}

// Moves folder `from` to the first free TARGET.KIND-N beside `target` and returns it.
static fs::path move_beside(const fs::path& from, const fs::path& target, const std::string& kind,
                            const std::string& what) {
  std::error_code ec;
  for (int n = 1;; ++n) {
    const fs::path p = target.parent_path() / (target.filename().string() + "." + kind + "-" + std::to_string(n));
    // RENAME_NOREPLACE: never onto anything, not even an empty folder (rename(2) would take it).
    if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, p.c_str(), RENAME_NOREPLACE) == 0) {
      sync_parent(p);
      return p;
    }
    const int e = errno;
    if (e == EEXIST) continue;
    if (e == EINVAL || e == ENOSYS || e == EOPNOTSUPP) {  // no RENAME_NOREPLACE here: check, then rename
      if (fs::exists(fs::symlink_status(p, ec))) continue;
      if (::rename(from.c_str(), p.c_str()) == 0) {
        sync_parent(p);
        return p;
      }
    }
    throw std::runtime_error(what + "cannot rename the results beside the earlier output: " + error_text(errno) +
                             "; the results are in " + from.string());
  }
}

fs::path rescue_staging(const std::string& out, pid_t pid) {
  const fs::path target = fs::absolute(normalise(out));
  const std::string prefix = "." + target.filename().string() + ".partial-" + std::to_string(pid) + "-";
  std::error_code ec;
  for (fs::directory_iterator it(target.parent_path(), ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().rfind(prefix, 0) != 0) continue;
    return move_beside(it->path(), target, "incomplete", "--out " + shown(out) + ": ");
  }
  return {};
}

int remove_stale_staging(const fs::path& target) noexcept {
  int removed = 0;
  try {
    const std::string prefix = "." + target.filename().string() + ".partial-";
    std::error_code ec;
    for (fs::directory_iterator it(target.parent_path(), ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.rfind(prefix, 0) != 0) continue;
      // ".NAME.partial-PID-N": PID and N decimal
      const std::string rest = name.substr(prefix.size());
      const auto dash = rest.find('-');
      if (dash == std::string::npos || dash == 0 || dash > 9 || dash + 1 >= rest.size()) continue;
      const std::string pid_text = rest.substr(0, dash), n_text = rest.substr(dash + 1);
      if (pid_text.find_first_not_of("0123456789") != std::string::npos ||
          n_text.find_first_not_of("0123456789") != std::string::npos)
        continue;
      const pid_t pid = static_cast<pid_t>(std::stol(pid_text));
      if (pid <= 0 || pid == ::getpid()) continue;
      if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // running (or not ours to ask): keep
      if (remove_output(it->path())) ++removed;
    }
  } catch (...) {}
  return removed;
}

StagedFolder::StagedFolder(const std::string& out, const std::string& tool, const std::string& option)
    : value_(out), option_(option), tool_(tool) {
  target_ = fs::absolute(check_output_dir(out, option));
  std::error_code ec;
  fs::create_directories(target_.parent_path(), ec);
  if (ec)
    throw std::runtime_error(option_ + " " + shown(value_) + ": cannot create " + target_.parent_path().string() +
                             ": " + ec.message());
  remove_stale_staging(target_);
  for (;;) {
    staging_ = unused_sibling(target_, "partial");
    if (::mkdir(staging_.c_str(), 0777) == 0) break;
    if (errno != EEXIST)
      throw std::runtime_error(option_ + " " + shown(value_) + ": cannot create " + staging_.string() + ": " +
                               error_text(errno));
  }
  std::ofstream m(staging_ / kMarkerFile, std::ios::binary);
  m << marker_text(tool);
  m.close();
  if (!m) {
    ::unlink((staging_ / kMarkerFile).c_str());
    ::rmdir(staging_.c_str());
    done_ = true;
    throw std::runtime_error(option_ + " " + shown(value_) + ": cannot write in " + staging_.string());
  }
}

void StagedFolder::write_text(const std::string& name, const std::string& text) const {
  const fs::path p = staging_ / name;
  std::ofstream f(p, std::ios::binary);
  f << text;
  f.close();
  if (!f) throw std::runtime_error(p.string() + ": write failed");
}

void StagedFolder::plot(const std::string& script, const interrupt::StopToken& stop) const {
  run_gnuplot(staging_,
              "set encoding utf8\nset datafile separator ','\nset terminal pngcairo size 1000,700 noenhanced\n"
              "set grid\nset key outside right top vertical\n" +
                  script,
              stop);
}

StagedFolder::~StagedFolder() {
  if (!done_) remove_output(staging_);
}

void StagedFolder::finish_marker(bool list_files) {
  const std::string what = option_ + " " + shown(value_) + ": ";
  // The marker lists what this run wrote: a later run replaces the folder only while it holds
  // nothing else (a user's notes put into it are refused, not deleted).
  if (list_files) {
    std::vector<std::string> files;
    std::error_code lec;
    for (fs::directory_iterator it(staging_, lec), end; !lec && it != end; it.increment(lec)) {
      const std::string name = it->path().filename().string();
      if (name != kMarkerFile && name.find('\n') == std::string::npos) files.push_back(name);
    }
    if (lec) throw std::runtime_error(what + "cannot list " + staging_.string() + ": " + lec.message());
    std::sort(files.begin(), files.end());
    std::string text = marker_text(tool_) + "files:\n";
    for (const auto& f : files) text += "file: " + f + "\n";
    write_file_atomically(staging_ / kMarkerFile, text);
  }
  sync_folder(staging_, what);
}

fs::path StagedFolder::commit_keeping_earlier(const std::string& kind, bool list_files) {
  if (done_) throw std::logic_error("StagedFolder::commit called twice");
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(target_, ec))) {
    // No earlier output: a rename, nothing to remove, so no warning (one would come only from
    // a folder put there in the instant since the check; commit() then replaces it only if it
    // is a feeddrive output or empty).
    (void)commit(list_files);
    return target_;
  }
  finish_marker(list_files);
  done_ = true;  // kept on failure from here: it holds the results
  return move_beside(staging_, target_, kind, option_ + " " + shown(value_) + ": ");
}

std::vector<std::string> StagedFolder::commit(bool list_files) {
  if (done_) throw std::logic_error("StagedFolder::commit called twice");
  const std::string what = option_ + " " + shown(value_) + ": ";
  const std::string kept = "; the results are in " + staging_.string();
  finish_marker(list_files);
  // From here on the staging folder is kept on failure: it holds finished results.
  done_ = true;
  std::error_code ec;
  const auto st = fs::symlink_status(target_, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw std::runtime_error(what + "cannot check it: " + ec.message() + kept);
  if (!fs::exists(st)) {
    if (::rename(staging_.c_str(), target_.c_str()) != 0)
      throw std::runtime_error(what + "cannot rename the results into place: " + error_text(errno) + kept);
    sync_parent(target_);
    return {};
  }
  // The results are in place; the previous output, moved to `old`, stays there when it cannot
  // be removed: a warning for the caller, not a failure.
  const auto removed = [&](const fs::path& old) -> std::vector<std::string> {
    if (remove_output(old)) return {};
    return {what + "could not remove the previous output, now in " + old.string()};
  };
  const auto ours = [](const fs::path& d) {
    return (is_feeddrive_output(d) && foreign_entry(d).empty()) || empty_folder(d);
  };
  if (!fs::is_directory(st) || !ours(target_))
    throw std::runtime_error(what +
                             "changed during the run: no longer a feeddrive output, or it holds files feeddrive did "
                             "not write; not replaced" +
                             kept);

  int err = 0;
  if (exchange(staging_, target_, err)) {
    sync_parent(target_);
    // staging_ now holds the previous output. Check it again: a folder that is not ours goes back.
    if (!ours(staging_)) {
      int err2 = 0;
      if (exchange(staging_, target_, err2))
        throw std::runtime_error(what +
                                 "changed during the run: no longer a feeddrive output, or it holds files feeddrive "
                                 "did not write; not replaced" +
                                 kept);
      throw std::runtime_error(what + "changed during the run; the folder found there was moved to " +
                               staging_.string() + " and could not be moved back (" + error_text(err2) + ")");
    }
    return removed(staging_);
  }
  if (err != EINVAL && err != ENOSYS && err != EOPNOTSUPP)
    throw std::runtime_error(what + "cannot swap the results into place: " + error_text(err) + kept);

  // No atomic exchange on this file system: previous output to a backup, new into place, backup
  // removed; the previous output is restored if the second rename fails.
  const fs::path backup = unused_sibling(target_, "previous");
  if (::rename(target_.c_str(), backup.c_str()) != 0)
    throw std::runtime_error(what + "cannot move the previous output aside: " + error_text(errno) + kept);
  if (::rename(staging_.c_str(), target_.c_str()) != 0) {
    const int e = errno;
    if (::rename(backup.c_str(), target_.c_str()) != 0)
      throw std::runtime_error(what + "cannot rename the results into place (" + error_text(e) +
                               "); the previous output is in " + backup.string() + kept);
    throw std::runtime_error(what + "cannot rename the results into place: " + error_text(e) + kept);
  }
  sync_parent(target_);
  return removed(backup);
}

}  // namespace feeddrive::output
