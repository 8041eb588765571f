#!/usr/bin/env bash
# feeddrive-keys --check fails when a whole generated table, marker and rows, is deleted from
# docs/scenario.md (the review of issue 22): a copy of the real document without the
# reference.step table must give exit 2 and a line naming reference.step, and the unchanged copy
# exit 0 (so the failure is the deletion's).
#   key_tables_missing_test.sh FEEDDRIVE-KEYS DOCS/SCENARIO.MD
set -euo pipefail
keys=$1 doc=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$doc" "$tmp/whole.md"
"$keys" --check "$tmp/whole.md" || { echo "FAIL: the unchanged copy does not pass"; exit 1; }
awk '/^<!-- keys: reference.step / { skip = 1 } !skip { print } skip && /^<!-- \/keys -->/ { skip = 0 }' \
  "$doc" > "$tmp/deleted.md"
grep -q "keys: reference.step" "$tmp/deleted.md" && { echo "FAIL: the table was not deleted"; exit 1; }
[ "$(wc -l < "$tmp/deleted.md")" -lt "$(wc -l < "$doc")" ] || { echo "FAIL: nothing deleted"; exit 1; }
rc=0
"$keys" --check "$tmp/deleted.md" 2> "$tmp/err" || rc=$?
cat "$tmp/err"
[ "$rc" = 2 ] || { echo "FAIL: exit $rc with the reference.step table deleted, not 2"; exit 1; }
[ "$(wc -l < "$tmp/err")" = 1 ] || { echo "FAIL: not one line"; exit 1; }
grep -q "reference.step" "$tmp/err" || { echo "FAIL: the message does not name reference.step"; exit 1; }
echo "ok: a deleted table fails the check (exit 2, names it)"
