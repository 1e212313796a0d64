#!/usr/bin/env bash
# The README's test command: installs the dependencies, builds, and runs every test (unit tests and the
# scenarios in scenarios/, label "scenario") but the 30-minute soak patrol (label "soak"; ctest --test-dir build
# -L soak). Exits non-zero when any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
# Disk: the build and the tests' outputs take about 1.5 GB, scripts/sanitize.sh's build-asan/ 2.5 GB more (a clean
# .ci/run peaked at 4.2 GB on 2026-12-05; 17 GB before the tests deleted their bags).
echo "test.sh: $(df -h --output=avail . | tail -1 | tr -d ' ') free on $(df --output=target . | tail -1)"
./scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 900 -LE soak
