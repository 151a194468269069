// GoogleTest-compatible subset for Cortex-M4 test images (no heap, exceptions or RTTI).
//
// Tests written for GoogleTest compile unchanged: TEST, TEST_F, EXPECT_/ASSERT_ EQ NE LT LE GT GE
// TRUE FALSE NEAR FLOAT_EQ DOUBLE_EQ STREQ STRNE, ADD_FAILURE, FAIL, SUCCEED. Streamed messages
// (`<< "why"`) compile and are dropped; the failing expression and both values are printed.
// The runner (runner.cpp) provides main(); output and the exit code travel over semihosting.
#pragma once
#pragma GCC system_header

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace testing {

/// Base of every test; fixtures override SetUp/TearDown as in GoogleTest.
class Test {
 public:
  virtual ~Test() = default;
  virtual void SetUp() {}
  virtual void TearDown() {}
  virtual void TestBody() = 0;
  static bool HasFatalFailure();
  static bool HasFailure();
};

/// Accepts and drops streamed failure messages.
class Message {
 public:
  template <class T>
  Message& operator<<(const T&) {
    return *this;
  }
};

namespace internal {

struct TestInfo {
  const char* suite;
  const char* name;
  void (*run)();
  TestInfo* next;
};

/// Links a test into the registry at static-initialisation time.
struct Registrar {
  explicit Registrar(TestInfo* info);
};

void RunTest(Test& test);

/// Fixed-capacity text for one failure report.
class Text {
 public:
  void Append(const char* s);
  void AppendSigned(std::int64_t v);
  void AppendUnsigned(std::uint64_t v);
  void AppendDouble(double v);
  void AppendHex(std::uintptr_t v);
  const char* c_str() const { return buffer_; }

 private:
  static constexpr std::size_t kCapacity = 200;
  char buffer_[kCapacity] = {};
  std::size_t size_ = 0;
};

template <class T>
void AppendValue(Text& text, const T& value) {
  using U = std::remove_cv_t<std::remove_reference_t<T>>;
  if constexpr (std::is_same_v<U, bool>) {
    text.Append(value ? "true" : "false");
  } else if constexpr (std::is_enum_v<U>) {
    AppendValue(text, static_cast<std::underlying_type_t<U>>(value));
  } else if constexpr (std::is_integral_v<U> && std::is_signed_v<U>) {
    text.AppendSigned(static_cast<std::int64_t>(value));
  } else if constexpr (std::is_integral_v<U>) {
    text.AppendUnsigned(static_cast<std::uint64_t>(value));
  } else if constexpr (std::is_floating_point_v<U>) {
    text.AppendDouble(static_cast<double>(value));
  } else if constexpr (std::is_same_v<U, const char*> || std::is_same_v<U, char*>) {
    text.Append(value == nullptr ? "(null)" : value);
  } else if constexpr (std::is_pointer_v<U>) {
    text.AppendHex(reinterpret_cast<std::uintptr_t>(value));
  } else if constexpr (std::is_array_v<U> &&
                       std::is_same_v<std::remove_cv_t<std::remove_extent_t<U>>, char>) {
    text.Append(value);
  } else {
    text.Append("(value)");
  }
}

}  // namespace internal

/// Outcome of one check, with the report text on failure.
class AssertionResult {
 public:
  explicit AssertionResult(bool ok) : ok_(ok) {}
  explicit operator bool() const { return ok_; }
  internal::Text& text() { return text_; }
  const char* message() const { return text_.c_str(); }

 private:
  bool ok_;
  internal::Text text_;
};

inline AssertionResult AssertionSuccess() { return AssertionResult(true); }

namespace internal {

// Each operand is evaluated exactly once (as in GoogleTest): the comparison runs here, on the
// values, inside this system header so mixed-sign comparisons warn no more than with GoogleTest.
#define VIBID_GTEST_OPERATOR_(Name, op)             \
  struct Name {                                     \
    template <class A, class B>                     \
    bool operator()(const A& a, const B& b) const { \
      return a op b;                                \
    }                                               \
  };
VIBID_GTEST_OPERATOR_(Eq, ==)
VIBID_GTEST_OPERATOR_(Ne, !=)
VIBID_GTEST_OPERATOR_(Lt, <)
VIBID_GTEST_OPERATOR_(Le, <=)
VIBID_GTEST_OPERATOR_(Gt, >)
VIBID_GTEST_OPERATOR_(Ge, >=)
#undef VIBID_GTEST_OPERATOR_

template <class Op, class A, class B>
AssertionResult Compare(Op op_fn, const char* ea, const char* op, const char* eb, const A& a,
                        const B& b) {
  AssertionResult r(op_fn(a, b));
  const bool ok = static_cast<bool>(r);
  if (!ok) {
    Text& t = r.text();
    t.Append("expected ");
    t.Append(ea);
    t.Append(" ");
    t.Append(op);
    t.Append(" ");
    t.Append(eb);
    t.Append(", got ");
    AppendValue(t, a);
    t.Append(" vs ");
    AppendValue(t, b);
  }
  return r;
}

inline AssertionResult Boolean(bool ok, const char* expr, const char* expected) {
  AssertionResult r(ok);
  if (!ok) {
    r.text().Append("expected ");
    r.text().Append(expr);
    r.text().Append(" to be ");
    r.text().Append(expected);
  }
  return r;
}

inline AssertionResult Near(const char* ea, const char* eb, const char* etol, double a, double b,
                            double tol) {
  const double diff = a > b ? a - b : b - a;
  AssertionResult r(diff <= tol);
  if (!r) {
    Text& t = r.text();
    t.Append("expected |");
    t.Append(ea);
    t.Append(" - ");
    t.Append(eb);
    t.Append("| <= ");
    t.Append(etol);
    t.Append(", got ");
    t.AppendDouble(a);
    t.Append(" vs ");
    t.AppendDouble(b);
  }
  return r;
}

/// GoogleTest's FLOAT_EQ/DOUBLE_EQ: equal within 4 units in the last place.
template <class F, class Bits>
AssertionResult UlpEq(const char* ea, const char* eb, F a, F b) {
  const auto biased = [](F v) {
    const Bits bits = std::bit_cast<Bits>(v);
    constexpr Bits kSign = Bits{1} << (sizeof(Bits) * 8 - 1);
    return (bits & kSign) ? static_cast<Bits>(~bits + 1) : static_cast<Bits>(bits | kSign);
  };
  const bool nan = (a != a) || (b != b);
  const Bits x = biased(a);
  const Bits y = biased(b);
  const Bits dist = x > y ? x - y : y - x;
  const bool ok = !nan && dist <= 4;
  return Compare([ok](const F&, const F&) { return ok; }, ea, "~=", eb, a, b);
}

inline AssertionResult StrEq(bool want_equal, const char* ea, const char* eb, const char* a,
                             const char* b) {
  const bool equal = (a == nullptr || b == nullptr) ? a == b : std::strcmp(a, b) == 0;
  const bool ok = equal == want_equal;
  return Compare([ok](const char*, const char*) { return ok; }, ea, want_equal ? "==" : "!=", eb, a,
                 b);
}

/// Records a failure; `=` so a streamed Message can follow the macro.
class AssertHelper {
 public:
  AssertHelper(const char* file, int line, const char* text, bool fatal)
      : file_(file), line_(line), text_(text), fatal_(fatal) {}
  void operator=(const Message&) const;

 private:
  const char* file_;
  int line_;
  const char* text_;
  bool fatal_;
};

}  // namespace internal
}  // namespace testing

#define VIBID_GTEST_CHECK_(result, on_failure)                                      \
  switch (0)                                                                        \
  case 0:                                                                           \
  default:                                                                          \
    if (const ::testing::AssertionResult vibid_gtest_ar = (result); vibid_gtest_ar) \
      ;                                                                             \
    else                                                                            \
      on_failure(vibid_gtest_ar.message())

#define VIBID_GTEST_NONFATAL_(text) \
  ::testing::internal::AssertHelper(__FILE__, __LINE__, text, false) = ::testing::Message()
#define VIBID_GTEST_FATAL_(text) \
  return ::testing::internal::AssertHelper(__FILE__, __LINE__, text, true) = ::testing::Message()

#define VIBID_GTEST_CMP_(a, Op, op, b, on_failure) \
  VIBID_GTEST_CHECK_(                              \
      ::testing::internal::Compare(::testing::internal::Op{}, #a, #op, #b, (a), (b)), on_failure)

#define EXPECT_EQ(a, b) VIBID_GTEST_CMP_(a, Eq, ==, b, VIBID_GTEST_NONFATAL_)
#define EXPECT_NE(a, b) VIBID_GTEST_CMP_(a, Ne, !=, b, VIBID_GTEST_NONFATAL_)
#define EXPECT_LT(a, b) VIBID_GTEST_CMP_(a, Lt, <, b, VIBID_GTEST_NONFATAL_)
#define EXPECT_LE(a, b) VIBID_GTEST_CMP_(a, Le, <=, b, VIBID_GTEST_NONFATAL_)
#define EXPECT_GT(a, b) VIBID_GTEST_CMP_(a, Gt, >, b, VIBID_GTEST_NONFATAL_)
#define EXPECT_GE(a, b) VIBID_GTEST_CMP_(a, Ge, >=, b, VIBID_GTEST_NONFATAL_)
#define ASSERT_EQ(a, b) VIBID_GTEST_CMP_(a, Eq, ==, b, VIBID_GTEST_FATAL_)
#define ASSERT_NE(a, b) VIBID_GTEST_CMP_(a, Ne, !=, b, VIBID_GTEST_FATAL_)
#define ASSERT_LT(a, b) VIBID_GTEST_CMP_(a, Lt, <, b, VIBID_GTEST_FATAL_)
#define ASSERT_LE(a, b) VIBID_GTEST_CMP_(a, Le, <=, b, VIBID_GTEST_FATAL_)
#define ASSERT_GT(a, b) VIBID_GTEST_CMP_(a, Gt, >, b, VIBID_GTEST_FATAL_)
#define ASSERT_GE(a, b) VIBID_GTEST_CMP_(a, Ge, >=, b, VIBID_GTEST_FATAL_)

#define EXPECT_TRUE(c)                                                               \
  VIBID_GTEST_CHECK_(::testing::internal::Boolean(static_cast<bool>(c), #c, "true"), \
                     VIBID_GTEST_NONFATAL_)
#define EXPECT_FALSE(c) \
  VIBID_GTEST_CHECK_(::testing::internal::Boolean(!(c), #c, "false"), VIBID_GTEST_NONFATAL_)
#define ASSERT_TRUE(c)                                                               \
  VIBID_GTEST_CHECK_(::testing::internal::Boolean(static_cast<bool>(c), #c, "true"), \
                     VIBID_GTEST_FATAL_)
#define ASSERT_FALSE(c) \
  VIBID_GTEST_CHECK_(::testing::internal::Boolean(!(c), #c, "false"), VIBID_GTEST_FATAL_)

#define EXPECT_NEAR(a, b, tol)                                                                    \
  VIBID_GTEST_CHECK_(::testing::internal::Near(#a, #b, #tol, static_cast<double>(a),              \
                                               static_cast<double>(b), static_cast<double>(tol)), \
                     VIBID_GTEST_NONFATAL_)
#define ASSERT_NEAR(a, b, tol)                                                                    \
  VIBID_GTEST_CHECK_(::testing::internal::Near(#a, #b, #tol, static_cast<double>(a),              \
                                               static_cast<double>(b), static_cast<double>(tol)), \
                     VIBID_GTEST_FATAL_)
#define EXPECT_DOUBLE_EQ(a, b)                                                              \
  VIBID_GTEST_CHECK_((::testing::internal::UlpEq<double, std::uint64_t>(#a, #b, (a), (b))), \
                     VIBID_GTEST_NONFATAL_)
#define ASSERT_DOUBLE_EQ(a, b)                                                              \
  VIBID_GTEST_CHECK_((::testing::internal::UlpEq<double, std::uint64_t>(#a, #b, (a), (b))), \
                     VIBID_GTEST_FATAL_)
#define EXPECT_FLOAT_EQ(a, b)                                                              \
  VIBID_GTEST_CHECK_((::testing::internal::UlpEq<float, std::uint32_t>(#a, #b, (a), (b))), \
                     VIBID_GTEST_NONFATAL_)
#define ASSERT_FLOAT_EQ(a, b)                                                              \
  VIBID_GTEST_CHECK_((::testing::internal::UlpEq<float, std::uint32_t>(#a, #b, (a), (b))), \
                     VIBID_GTEST_FATAL_)
#define EXPECT_STREQ(a, b) \
  VIBID_GTEST_CHECK_(::testing::internal::StrEq(true, #a, #b, (a), (b)), VIBID_GTEST_NONFATAL_)
#define EXPECT_STRNE(a, b) \
  VIBID_GTEST_CHECK_(::testing::internal::StrEq(false, #a, #b, (a), (b)), VIBID_GTEST_NONFATAL_)
#define ASSERT_STREQ(a, b) \
  VIBID_GTEST_CHECK_(::testing::internal::StrEq(true, #a, #b, (a), (b)), VIBID_GTEST_FATAL_)
#define ASSERT_STRNE(a, b) \
  VIBID_GTEST_CHECK_(::testing::internal::StrEq(false, #a, #b, (a), (b)), VIBID_GTEST_FATAL_)

#define ADD_FAILURE() VIBID_GTEST_NONFATAL_("failure")
#define FAIL() VIBID_GTEST_FATAL_("failure")
#define SUCCEED() static_cast<void>(0)

#define VIBID_GTEST_CLASS_(suite, name) suite##_##name##_Test

#define VIBID_GTEST_DEFINE_(suite, name, parent)                          \
  class VIBID_GTEST_CLASS_(suite, name) : public parent {                 \
   public:                                                                \
    void TestBody() override;                                             \
    static void Run() {                                                   \
      VIBID_GTEST_CLASS_(suite, name) test;                               \
      ::testing::internal::RunTest(test);                                 \
    }                                                                     \
    static ::testing::internal::TestInfo info;                            \
    static const ::testing::internal::Registrar registrar;                \
  };                                                                      \
  ::testing::internal::TestInfo VIBID_GTEST_CLASS_(suite, name)::info = { \
      #suite, #name, &VIBID_GTEST_CLASS_(suite, name)::Run, nullptr};     \
  const ::testing::internal::Registrar VIBID_GTEST_CLASS_(                \
      suite, name)::registrar{&VIBID_GTEST_CLASS_(suite, name)::info};    \
  void VIBID_GTEST_CLASS_(suite, name)::TestBody()

#define TEST(suite, name) VIBID_GTEST_DEFINE_(suite, name, ::testing::Test)
#define TEST_F(fixture, name) VIBID_GTEST_DEFINE_(fixture, name, fixture)
