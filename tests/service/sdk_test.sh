#!/usr/bin/env bash
# The SDK for external controllers: `cmake --install` of this build into a temporary prefix, the
# out-of-tree example examples/cpp (find_package(feeddrive), the project's sliding-mode law over
# LCM) configured and built against it alone, linked without CVODE, then run as the controller
# of the paper's jerk-limited move with feeddrive-launch --external controller. It configures
# itself from run_info_t.
source "$(dirname "$0")/lib.sh" "$@"
source "$(dirname "$0")/sdk_check.sh"
sdk_check "$BUILD"
