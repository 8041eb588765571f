#!/usr/bin/env bash
# An offline tool never links the bus (issue 22, point 1): feeddrive-fit, feeddrive-log2csv and
# the libraries under them (feeddrive::fit, feeddrive::record) link no feeddrive::service, no
# liblcm and no libcrypto, and the libraries no CLI11 either. Checked on the built files, at
# link level: `ldd` for the shared libraries a file needs (liblcm, libcrypto, a shared
# libfeeddrive_service), `nm` for what a static link pulled in (feeddrive::service code,
# liblcm's C API lcm_*, OpenSSL's EVP_/HMAC, CLI11's CLI::). Usage:
#   offline_links_test.sh exe:<file>... lib:<file>...
# exe: a program (its own CLI may use CLI11); lib: a library (no CLI11 either).
set -euo pipefail
fail=0
check() {  # $1 kind, $2 file
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
  fi
  [ "$fail" -eq 0 ] && echo "ok: $f ($kind) links no bus"
  return 0
}
[ $# -gt 0 ] || { echo "usage: $0 exe:<file>|lib:<file>..."; exit 2; }
for a in "$@"; do check "${a%%:*}" "${a#*:}"; done
exit "$fail"
