# Host dependencies, all from Debian packages installed by scripts/setup.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.11 REQUIRED)
find_package(CLI11 2.1 REQUIRED)
find_package(GTest REQUIRED)
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(HIDAPI REQUIRED IMPORTED_TARGET hidapi-hidraw)
pkg_check_modules(LIBUSB REQUIRED IMPORTED_TARGET libusb-1.0)

option(VIBID_BENCHMARKS "Build the Google Benchmark programs in bench/" ON)
# The asan preset turns it off: the CLI is a thin front end over the libraries, whose tests, the
# bench's and the fuzzers run under the sanitizers; the CLI's own tests and the hil suite that
# drives it run in the optimised build (and the hil suite again on QEMU). It saves CI about a
# quarter of the sanitizer build and of its test run (docs/testing.md).
option(VIBID_CLI "Build the vibid CLI, its tests and the hil suite that drives it" ON)
# Google Benchmark is a test tool (scripts/setup --for test): without it the benchmarks are left
# out, and the documented benchmark commands fail scripts/test's smoke phase (benchmarks/smoke.py).
if(VIBID_BENCHMARKS)
  find_package(benchmark QUIET)
  if(NOT benchmark_FOUND)
    message(STATUS "Google Benchmark not found (scripts/setup --for test installs it): "
                   "benchmarks/ is not built")
  endif()
endif()

# kissfft's C++ header (kissfft.hh) is a header-only template, used in double precision.
find_path(KISSFFT_INCLUDE_DIR kissfft.hh PATH_SUFFIXES kissfft REQUIRED)
add_library(vibid_kissfft INTERFACE)
target_include_directories(vibid_kissfft SYSTEM INTERFACE ${KISSFFT_INCLUDE_DIR})
