#!/usr/bin/env bash
# Installs every build, test and run dependency of feeddrive on Debian 12 (bookworm).
# Idempotent: apt-get skips what is already installed. Uses sudo when not root.
# The JDK (default-jdk-headless) builds the jar of the message types that lcm-spy needs
# (docs/lcm-contract.md), tested by tests/service/lcm_spy_jar_test.sh; a build without one skips
# that jar and its test with a message.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(
  build-essential cmake pkg-config git
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java libglib2.0-dev default-jdk-headless
  libeigen3-dev libsundials-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
  libbenchmark-dev libceres-dev libssl-dev
  libopenmpi-dev openmpi-bin
  gnuplot-nox jq python3 python3-yaml clang-format
  iproute2 nftables util-linux procps rt-tests stress-ng
  lua5.2 liblcm-lua lua-luaossl
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
