#!/usr/bin/env bash
# The longer tuning run (issue 24, item 2; docs/tuning.md): scripts/tune.py on
# studies/tuning_long.yaml (full-factorial design corners with two noise seeds, 27 candidates per
# family), then the same test set as studies/tuning.yaml. Prints the wall time; the tables are in
# OUT/design.md and OUT/test.md. Not a test: about 1.5 h on the shared 2 cores.
#   nice -n 10 bash bench/tuning_bench.sh [BUILD_DIR] [OUT] [JOBS]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=${2:-out/tuning_long}
JOBS=${3:-2}
start=$(date +%s)
python3 scripts/tune.py studies/tuning_long.yaml --out "$OUT" --bin "$BUILD/bin" -j "$JOBS"
echo "tuning_long: $(( $(date +%s) - start )) s wall; $OUT/design.md, $OUT/test.md"
