// The runner behind include/gtest/gtest.h: registry, per-test failure state, GoogleTest-style
// console output, and RunAllTests() whose return value becomes the emulator's exit status.
#include <gtest/gtest.h>

#include <cstdint>

#include "runner.hpp"
#include "semihosting.hpp"

namespace testing {
namespace {

internal::TestInfo* g_first = nullptr;
internal::TestInfo* g_last = nullptr;
bool g_failed = false;
bool g_fatal = false;

void Print(const char* s) { vibid::testing::SemihostWrite(s); }

void PrintNumber(std::uint64_t v) {
  internal::Text t;
  t.AppendUnsigned(v);
  Print(t.c_str());
}

}  // namespace

bool Test::HasFatalFailure() { return g_fatal; }
bool Test::HasFailure() { return g_failed; }

namespace internal {

Registrar::Registrar(TestInfo* info) {
  // Keep definition order, as GoogleTest does within a file.
  if (g_last == nullptr) {
    g_first = info;
  } else {
    g_last->next = info;
  }
  g_last = info;
}

void RunTest(Test& test) {
  test.SetUp();
  if (!g_fatal) test.TestBody();
  test.TearDown();
}

void AssertHelper::operator=(const Message&) const {
  g_failed = true;
  if (fatal_) g_fatal = true;
  Text where;
  where.Append(file_);
  where.Append(":");
  where.AppendSigned(line_);
  where.Append(": Failure\n");
  Print(where.c_str());
  Print(text_);
  Print("\n");
}

void Text::Append(const char* s) {
  while (*s != '\0' && size_ + 1 < kCapacity) buffer_[size_++] = *s++;
  buffer_[size_] = '\0';
}

void Text::AppendUnsigned(std::uint64_t v) {
  char digits[21];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  char out[21];
  for (int i = 0; i < n; ++i) out[i] = digits[n - 1 - i];
  out[n] = '\0';
  Append(out);
}

void Text::AppendSigned(std::int64_t v) {
  if (v < 0) {
    Append("-");
    AppendUnsigned(static_cast<std::uint64_t>(-(v + 1)) + 1);
  } else {
    AppendUnsigned(static_cast<std::uint64_t>(v));
  }
}

void Text::AppendHex(std::uintptr_t v) {
  char out[2 + 2 * sizeof(v) + 1] = {'0', 'x'};
  for (std::size_t i = 0; i < 2 * sizeof(v); ++i) {
    const auto nibble = static_cast<unsigned>((v >> (4 * (2 * sizeof(v) - 1 - i))) & 0xFu);
    out[2 + i] = static_cast<char>(nibble < 10 ? '0' + nibble : 'a' + nibble - 10);
  }
  out[sizeof(out) - 1] = '\0';
  Append(out);
}

// Scientific notation with 9 significant digits: enough to see why a comparison failed.
void Text::AppendDouble(double v) {
  if (v != v) {
    Append("nan");
    return;
  }
  if (v < 0) {
    Append("-");
    v = -v;
  }
  if (v > 1.7e308) {
    Append("inf");
    return;
  }
  int exponent = 0;
  if (v != 0.0) {
    while (v >= 10.0) {
      v /= 10.0;
      ++exponent;
    }
    while (v < 1.0) {
      v *= 10.0;
      --exponent;
    }
  }
  auto mantissa = static_cast<std::uint64_t>(v * 1e8 + 0.5);
  if (mantissa >= 1000000000u) {
    mantissa /= 10;
    ++exponent;
  }
  char frac[10];
  for (int i = 7; i >= 0; --i) {
    frac[i] = static_cast<char>('0' + mantissa % 10);
    mantissa /= 10;
  }
  frac[8] = '\0';
  AppendUnsigned(mantissa);
  Append(".");
  Append(frac);
  Append("e");
  AppendSigned(exponent);
}

}  // namespace internal
}  // namespace testing

namespace vibid::testing {

int RunAllTests() {
  using ::testing::internal::TestInfo;
  std::uint64_t total = 0;
  std::uint64_t failed = 0;
  for (TestInfo* t = ::testing::g_first; t != nullptr; t = t->next) ++total;
  ::testing::Print("[==========] Running ");
  ::testing::PrintNumber(total);
  ::testing::Print(" tests on Cortex-M4.\n");
  for (TestInfo* t = ::testing::g_first; t != nullptr; t = t->next) {
    ::testing::g_failed = false;
    ::testing::g_fatal = false;
    ::testing::internal::Text name;
    name.Append(t->suite);
    name.Append(".");
    name.Append(t->name);
    ::testing::Print("[ RUN      ] ");
    ::testing::Print(name.c_str());
    ::testing::Print("\n");
    t->run();
    ::testing::Print(::testing::g_failed ? "[  FAILED  ] " : "[       OK ] ");
    ::testing::Print(name.c_str());
    ::testing::Print("\n");
    if (::testing::g_failed) ++failed;
  }
  ::testing::Print("[==========] ");
  ::testing::PrintNumber(total);
  ::testing::Print(" tests ran.\n");
  if (failed == 0) {
    ::testing::Print("[  PASSED  ] ");
    ::testing::PrintNumber(total);
    ::testing::Print(" tests.\n");
    return 0;
  }
  ::testing::Print("[  FAILED  ] ");
  ::testing::PrintNumber(failed);
  ::testing::Print(" tests.\n");
  return 1;
}

}  // namespace vibid::testing
