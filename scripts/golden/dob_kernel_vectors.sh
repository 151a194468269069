#!/usr/bin/env bash
# Regenerates shared/fixed/testdata/dob_kernel_vectors.inc with the host build of the fixed-point
# kernel. The Cortex-M4 test (shared_fixed_kernel_test under the firmware preset) must then still
# reproduce the expected output bit for bit.
set -euo pipefail
cd "$(dirname "$0")/../.."
cmake --preset host >/dev/null
cmake --build --preset host --target dob_kernel_vectors
mkdir -p shared/fixed/testdata
./build/host/host/lib/dob/dob_kernel_vectors shared/fixed/testdata/dob_kernel_vectors.inc
