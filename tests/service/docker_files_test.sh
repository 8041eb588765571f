#!/usr/bin/env bash
# Runs tests/docker/dockerfile_test.sh under ctest (this folder's *_test.sh are registered): CI has
# no Docker engine, so this static check is what keeps docker/Dockerfile, docker/compose.yaml and
# .dockerignore in step with the scripts and executables CI builds (docs/deployment.md).
source "$(dirname "$0")/lib.sh" "$@"
command -v python3 >/dev/null || fail "python3 is not installed (scripts/install-deps.sh installs python3 and python3-yaml)"
bash "$SRC/tests/docker/dockerfile_test.sh" "$SRC"
