#!/usr/bin/env bash
# An offline tool never links the bus (issue 22, point 1): feeddrive-fit, feeddrive-log2csv and
# the libraries under them (feeddrive::fit, feeddrive::record) link no feeddrive::service (nor
# feeddrive::monitor), no LCM and no OpenSSL, and the libraries no CLI11 either. Three checks:
#   closure:<file>  the CMake link closure of each target (tests/record/link_closure.cmake writes
#                   it at configure time): no forbidden target or library anywhere in it. This is
#                   the check that holds: gcc links with --as-needed, so a library that is linked
#                   but never called leaves no trace in the built file for ldd or nm to see.
#   src:<dir>       no source or header under <dir> includes a feeddrive/service/ or
#                   feeddrive/monitor/ header, LCM's or OpenSSL's.
#   exe:<file>, lib:<file>  the built file: `ldd` for the shared libraries it needs (liblcm,
#                   libcrypto, a shared libfeeddrive_service), `nm` for what a static link pulled in
#                   (feeddrive::service code, liblcm's C API lcm_*, OpenSSL's EVP_/HMAC, CLI11's
#                   CLI::). exe: a program (its own CLI may use CLI11); lib: a library (no CLI11).
set -euo pipefail
fail=0
bus_names='feeddrive_service|feeddrive::service|feeddrive_monitor|feeddrive::monitor|PkgConfig::LCM|lcm|OpenSSL::[A-Za-z]+|ssl|crypto|(.*/)?lib(lcm|ssl|crypto)[.][^ ]*'
check_closure() {  # $1 the file link_closure.cmake wrote
  local f=$1 line tgt type names bad
  [ -s "$f" ] || { echo "FAIL: $f does not exist or is empty"; fail=1; return; }
  while IFS= read -r line; do
    tgt=${line%% *}
    type=${line#* }; type=${type%%:*}
    names=$(tr ' ' '\n' <<<"${line#*: }")
    bad="^($bus_names)\$"
    [ "$type" = EXECUTABLE ] || bad="^($bus_names|CLI11::CLI11|CLI11)\$"
    if grep -E "$bad" <<<"$names" | sort -u | tr '\n' ' ' | grep .; then
      echo "FAIL: $tgt ($type) links the above (through its CMake link closure)"; fail=1
    else
      echo "ok: $tgt ($type): link closure without the bus, LCM or OpenSSL$([ "$type" = EXECUTABLE ] || echo ' or CLI11')"
    fi
  done < "$f"
}
check_sources() {  # $1 a source folder or file
  local hits
  hits=$(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"](feeddrive/(service|monitor)/|lcm/|openssl/)' "$1" || true)
  if [ -n "$hits" ]; then
    echo "$hits"; echo "FAIL: sources under $1 include the bus (the headers above)"; fail=1
  else
    echo "ok: no source under $1 includes feeddrive/service/, feeddrive/monitor/, lcm/ or openssl/"
  fi
}
check_file() {  # $1 kind, $2 file
  local kind=$1 f=$2 deps syms
  [ -e "$f" ] || { echo "FAIL: $f does not exist"; fail=1; return; }
  if [ "$kind" = exe ] || [[ "$f" == *.so* ]]; then
    deps=$(ldd "$f" | awk '{print $1}')
    if grep -E '^(liblcm|libcrypto|libssl|libfeeddrive_service|libfeeddrive_monitor)' <<<"$deps"; then
      echo "FAIL: $f needs the shared libraries above (the bus)"; fail=1
    fi
  fi
  # Defined or undefined, every symbol the file holds or asks for (demangled).
  syms=$(nm -C "$f" 2>/dev/null | awk '{ $1 = ""; print }' | sed 's/^ *[A-Za-z] //')
  local bad='feeddrive::service::|^ *lcm_(create|publish|subscribe|handle|destroy)|lcm::LCM|^ *(EVP_|HMAC)'
  [ "$kind" = lib ] && bad="$bad|CLI::"
  if grep -E "$bad" <<<"$syms" | sort -u | head -5 | grep .; then
    echo "FAIL: $f holds or needs the symbols above (the bus, liblcm, OpenSSL or CLI11)"; fail=1
  else
    echo "ok: $f ($kind): no bus in ldd or nm"
  fi
}
[ $# -gt 0 ] || { echo "usage: $0 closure:<file>|src:<dir>|exe:<file>|lib:<file>..."; exit 2; }
for a in "$@"; do
  case "${a%%:*}" in
    closure) check_closure "${a#*:}" ;;
    src) check_sources "${a#*:}" ;;
    exe | lib) check_file "${a%%:*}" "${a#*:}" ;;
    *) echo "offline_links_test: unknown argument $a"; exit 2 ;;
  esac
done
exit "$fail"
