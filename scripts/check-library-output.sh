#!/usr/bin/env bash
# Libraries never print or exit (issue 22, point 3; docs/contributing.md, "Errors, logging and
# Ctrl-C"): they return results, throw typed errors, or log through spdlog, which the tool set up
# (tool::setup_logging). This check fails with FILE:LINE for every print to stdout/stderr (printf,
# fprintf, puts, fputs, fputc, putchar, perror, std::cout/cerr/clog, a write(2) to fd 1 or 2, the
# names stdout/stderr) and every exit (exit, _exit, _Exit, quick_exit, abort, std::terminate) in
# library code; comments are skipped. An allowed line (below, each with its reason) that no longer
# exists fails too: the list cannot outlive its reasons. ctest runs it (tests/CMakeLists.txt:
# lint.library_output).
#
# Library code: every C/C++ file of the repository except the tools' own files (*/apps/*, files
# named main.cpp or *_main.cpp), common/tool/ (the tools' one report path: linked only by tools,
# common/CMakeLists.txt), tests/, bench/ and examples/.
set -euo pipefail
cd "$(dirname "$0")/.."

# The allowed lines, each FILE, a regular expression its line must match, and why.
allow=(
  # A forked child between fork and exec has no caller to return an error to and may make only
  # system calls: its exit code (126, 127) tells the parent what failed.
  'common/output/src/gnuplot.cpp' '::_exit\(12[67]\)'
  'service/src/launch.cpp' '::_exit\((127|143)\)'
  # The same child's warnings and exec failure: write(2) of lines made before fork (no stdio,
  # whose lock another thread may hold at fork); its stderr is the launcher's.
  'service/src/launch.cpp' '::write\(2, line\.data\(\)'
  # The MPI transport's abort, called when a study stops: only MPI_Abort ends the other ranks of
  # an MPI job, which may be blocked in MPI_Probe (a throw on this rank cannot reach them);
  # _Exit only follows it for [[noreturn]]. Without MPI there is no such transport.
  'study/include/feeddrive/study/transport.hpp' 'virtual void abort\(int code\) = 0;'
  'study/src/transport.cpp' 'void abort\(int code\) override'
  'study/src/transport.cpp' 'std::_Exit\(code\);'
  # feeddrive-study's progress bar: compiled only into the feeddrive-study executable
  # (study/CMakeLists.txt), never into feeddrive::study.
  'study/src/progress.cpp' 'std::fput(s|c)\(.*stderr\)|std::fflush\(stderr\)'
)

print='(^|[^A-Za-z0-9_])(printf|fprintf|vprintf|vfprintf|puts|fputs|fputc|putchar|perror)[[:space:]]*\(|std::(cout|cerr|clog)([^A-Za-z0-9_]|$)|(^|[^A-Za-z0-9_])std(out|err)([^A-Za-z0-9_]|$)|write\([[:space:]]*[12][[:space:]]*,'
quit='(^|[^A-Za-z0-9_.>])(std::|::)?(exit|_exit|_Exit|quick_exit|abort|terminate)[[:space:]]*\('

if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.cc' '*.c' '*.h')
else
  mapfile -t files < <(find . -name 'build*' -prune -o -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.cc' \
    -o -name '*.c' -o -name '*.h' \) -print | sed 's#^\./##' | sort)
fi

bad=0 checked=0
used=()
for f in "${files[@]}"; do
  case "$f" in
    tests/* | bench/* | examples/* | */apps/* | common/tool/* | main.cpp | */main.cpp | *_main.cpp) continue ;;
  esac
  checked=$((checked + 1))
  while IFS= read -r hit; do
    code=${hit#*:}
    [[ "$code" =~ ^[[:space:]]*(//|\*|/\*) ]] && continue  # a comment
    [[ "${code%%[[:space:]]//*}" =~ $print|$quit ]] || continue  # only in a comment after the code
    ok=0
    for ((i = 0; i < ${#allow[@]}; i += 2)); do
      if [ "$f" = "${allow[i]}" ] && [[ "$code" =~ ${allow[i + 1]} ]]; then
        ok=1
        used[i]=1
        break
      fi
    done
    [ "$ok" = 1 ] && continue
    echo "$f:${hit%%:*}: a library prints or exits: ${code#"${code%%[![:space:]]*}"}" >&2
    bad=$((bad + 1))
  done < <(grep -nE "$print|$quit" "$f" || true)
done
for ((i = 0; i < ${#allow[@]}; i += 2)); do
  [ -n "${used[i]:-}" ] || { echo "check-library-output: allowed but not found (remove it): ${allow[i]}: ${allow[i + 1]}" >&2; bad=$((bad + 1)); }
done
if [ "$bad" -gt 0 ]; then
  echo "check-library-output: $bad line(s) in library code print or exit: return the result or the warnings, throw a" \
    "typed error (feeddrive/common/errors.hpp), or log through spdlog; the tool reports (common/tool)" >&2
  exit 1
fi
echo "check-library-output: $checked library files, none prints or exits"
