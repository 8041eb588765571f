#pragma once
// The output folder of every feeddrive tool (feeddrive-sim, -monitor, -launch, -log2csv, -fit):
// the one implementation of "--out DIR is checked before any work, written atomically, and never
// replaces anything feeddrive did not write".
//
//   check_output_dir(out)  before any work: normalises the path ("prev/" is "prev") and throws
//                          std::invalid_argument "--out DIR: why" (one line; the tools exit 2) if
//                          DIR names no folder of its own ("", "/", ".", ".."), is too long,
//                          lies under a file, cannot be written, or exists and is neither empty
//                          nor a feeddrive output holding only what feeddrive wrote.
//   StagedFolder           the one writer of every tool's results: a new sibling folder
//                          ".NAME.partial-PID-N" (marked from the start) that the tool fills
//                          (write_text, CsvWriter on path(), plot) and commit() swaps into place.
//                          A failure before or during commit never deletes the previous output or
//                          anything else; an exception, Ctrl-C or SIGTERM (the tools poll
//                          feeddrive/common/interrupt.hpp and unwind) removes the staging folder,
//                          and a staging folder left by a process that was killed (-9, power) is
//                          removed by the next run that writes the same DIR.
//
// A folder is a feeddrive output only if it holds the marker file `.feeddrive-output` that a
// StagedFolder wrote (first line "feeddrive-output", then "format: 1" and "tool: NAME"; commit()
// adds "files:" and one "file: NAME" line per entry it wrote). Outputs of feeddrive versions
// without the marker are refused like any other folder, and so is an output that holds an entry
// its marker does not list (a user's file put into it): replacing it would delete that file.

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::output {

inline constexpr const char* kMarkerFile = ".feeddrive-output";
inline constexpr int kFormatVersion = 1;

/// The marker's text for `tool`.
std::string marker_text(const std::string& tool);

/// True if `dir` is a folder (not a symbolic link) holding a well-formed marker.
bool is_feeddrive_output(const std::filesystem::path& dir);

/// The first entry of feeddrive output `dir` that its marker does not list (a file the user put
/// there), or "" if there is none, or the marker has no list (an older output).
std::string foreign_entry(const std::filesystem::path& dir);

/// The tool named in the marker of `dir` ("feeddrive-sim", ...), or "" if `dir` is not a
/// feeddrive output.
std::string output_tool(const std::filesystem::path& dir);

/// Writes `text` to `path` through a sibling temporary file renamed into place: a reader (or a
/// run that was interrupted) sees the old file or the new one, never half of one. Throws
/// std::runtime_error on failure (the temporary file is removed).
void write_file_atomically(const std::filesystem::path& path, const std::string& text);

/// `value` as the tools show it in a message: control characters and bytes that are not
/// printable ASCII become '?', an empty value is "".
std::string shown(const std::string& value);

/// The lexically normal form of `out` without trailing separators. Throws std::invalid_argument
/// ("<option> <value>: ...") for a path that names no folder of its own: "", "/", ".", "..",
/// "a/..".
std::filesystem::path normalise(const std::string& out, const std::string& option = "--out");

/// Everything that can be checked before the work: see the top of this file. Returns the
/// normalised path. Throws std::invalid_argument, one line naming the option and the value.
std::filesystem::path check_output_dir(const std::string& out, const std::string& option = "--out");

/// Throws std::invalid_argument ("<file_option> <file>: lies inside --out DIR ...") if the file
/// `file` (another output of the same run, e.g. --lcm-log) lies inside the output folder `out`,
/// which commit() replaces whole. "" is never inside.
void check_outside(const std::string& file, const std::string& file_option, const std::string& out,
                   const std::string& option = "--out");

/// Everything about an output file (--lcm-log) that can be checked before any work: its folder
/// exists and is writable, and the file, if it exists, is a regular file this user can write
/// (not a FIFO, which would block the writer's open(), a device or a folder). Throws
/// std::invalid_argument, one line naming the option, the value and what is wrong. "" passes.
/// An existing, non-empty file is replaced only if it starts with `magic` (e.g. an LCM log's
/// first four bytes): a user's scenario, key or other file is never overwritten. Empty `magic`:
/// any file may be replaced.
void check_output_file(const std::string& file, const std::string& option, const std::string& magic = "");

/// After the process `pid` that wrote `out` died unfinished (SIGKILL: no unwinding), moves the
/// staging folder it left (its record so far) to the first free OUT.incomplete-N beside `out`
/// and returns that path; "" when it left none. A later run would otherwise remove it as stale.
std::filesystem::path rescue_staging(const std::string& out, pid_t pid);

/// A new output folder written in a sibling temporary folder and swapped into place by commit().
class StagedFolder {
 public:
  /// Runs check_output_dir (std::invalid_argument), creates missing parent folders and the
  /// temporary folder with its marker (std::runtime_error on failure).
  StagedFolder(const std::string& out, const std::string& tool, const std::string& option = "--out");
  /// Removes the temporary folder unless commit() succeeded or kept it.
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// Where to write the files (absolute).
  const std::filesystem::path& dir() const { return staging_; }
  /// dir() / name.
  std::filesystem::path path(const std::string& name) const { return staging_ / name; }
  /// Writes dir()/name; throws std::runtime_error naming the file.
  void write_text(const std::string& name, const std::string& text) const;
  /// Runs a gnuplot script in dir() (run_gnuplot) after the preamble every feeddrive plot shares:
  /// UTF-8, comma-separated data, 1000x700 PNG (cairo, no enhanced text), grid, key to the right of the plot
  /// (clear of the title above it).
  void plot(const std::string& script, const interrupt::StopToken& stop) const;
  /// The final folder (absolute, normalised).
  const std::filesystem::path& target() const { return target_; }

  /// Puts the folder in place: renames it to the target if there is none, else exchanges the two
  /// atomically (renameat2 RENAME_EXCHANGE; where the file system lacks it, the old folder is
  /// renamed to a sibling backup first and restored if the second rename fails), then removes
  /// the old folder, which is a feeddrive output or empty (checked again). If the target has
  /// become something else meanwhile, nothing is replaced: throws std::runtime_error naming the
  /// temporary folder, which is kept with the results. With `list_files` (the default) the
  /// marker lists every entry written (see the top of this file); a folder that keeps growing
  /// after the commit (feeddrive-study's, over reruns) is committed without the list. Every file
  /// and folder in it is flushed to disk (fsync) before the rename, and the parent after it: a
  /// power cut never leaves the target with empty or short files. Returns the warnings, one line
  /// each, for the caller to report (this library prints nothing): the results are in place but
  /// the previous output could not be removed ("--out DIR: could not remove the previous output,
  /// now in PATH").
  [[nodiscard]] std::vector<std::string> commit(bool list_files = true);
  /// Like commit(), but an earlier output in the target is kept: the folder goes to the target
  /// if there is none, else to the first free sibling "TARGET.KIND-N" (N = 1, 2, ...; never onto
  /// anything). Returns where it went. For a record that must not replace a complete one (the
  /// monitor's record of an interrupted or failed run).
  std::filesystem::path commit_keeping_earlier(const std::string& kind, bool list_files = true);

 private:
  // Writes the marker's file list (when asked) and flushes every file and the folder to disk.
  void finish_marker(bool list_files);
  std::string value_;  // as the user gave it, for messages
  std::string option_;
  std::string tool_;
  std::filesystem::path target_;
  std::filesystem::path staging_;
  bool done_{false};
};

/// Removes the staging folders ".NAME.partial-PID-N" next to `target` that a feeddrive process
/// left when it was killed: only marked ones (is_feeddrive_output) whose PID is not running.
/// Returns how many were removed. StagedFolder's constructor calls it.
int remove_stale_staging(const std::filesystem::path& target) noexcept;

/// Puts folder `fresh` in the place of `target` (a folder inside an output that this process
/// owns, e.g. a study's plots/): flushed to disk, then renamed, or exchanged atomically with the
/// old one (renameat2 RENAME_EXCHANGE), which is then removed. Throws std::runtime_error.
void replace_folder(const std::filesystem::path& fresh, const std::filesystem::path& target);

/// Removes `dir` with everything in it only if it is a feeddrive output or an empty folder;
/// returns false (and removes nothing) otherwise or on failure.
bool remove_output(const std::filesystem::path& dir) noexcept;

}  // namespace feeddrive::output
