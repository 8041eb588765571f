#pragma once
// Plots with gnuplot, without ever letting text from the user run as gnuplot commands.
//
// The rules every plot script of feeddrive follows:
//   * data files have fixed, safe names (timeseries.csv, replay.csv, ...) inside the folder the
//     script runs in: no path, file name or column name from the user appears in a script;
//   * every other text (a title made from a scenario name, an effect name, an axis label) goes
//     in through gnuplot_string(), the one escaping rule;
//   * gnuplot runs without a shell, in the output folder (run_gnuplot).

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::output {

/// `text` as a gnuplot double-quoted string literal that can only ever be text. Kept: ASCII
/// letters, digits, space and _ - . , : ; + / ( ) [ ] = # % * ! ? < > | ~ ^ &, and well-formed
/// UTF-8 characters from U+00A0 up. Every other byte becomes '?': the quotes " and ', backslash
/// (gnuplot's escape character in double quotes), backquote (command substitution, which gnuplot
/// performs even inside double quotes), @ (macros), $, braces, control characters (newline ends a
/// command) and bytes that are not well-formed UTF-8. So no quote can end the literal and no
/// backquote, macro or escape sequence is ever interpreted; "system(...)" stays plain text.
/// At most max_bytes of text are kept (cut at a character boundary, then "...").
std::string gnuplot_string(std::string_view text, std::size_t max_bytes = 200);

/// Writes `script` to dir/script_name and runs `gnuplot script_name` in `dir` (fork and exec, no
/// shell; output to dir/gnuplot.log, removed on success). script_name is a fixed name chosen by
/// the caller, never the user's. Throws std::runtime_error with gnuplot's last message on failure;
/// when `stop` asks to stop (Ctrl-C), kills gnuplot and throws interrupt::Interrupted.
void run_gnuplot(const std::filesystem::path& dir, const std::string& script, const interrupt::StopToken& stop,
                 const std::string& script_name = "plots.gp");

}  // namespace feeddrive::output
