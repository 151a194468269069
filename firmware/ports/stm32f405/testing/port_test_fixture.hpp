// Common fixture: a cleared fake register file per test.
#pragma once

#include <gtest/gtest.h>

#include "fake_registers.hpp"

namespace vibid::fw::stm32::test {

class PortTest : public ::testing::Test {
 protected:
  void SetUp() override { regs().Clear(); }
  void TearDown() override { regs().Clear(); }
  static FakeRegisters& regs() { return FakeRegisters::Get(); }
  static constexpr std::size_t kNone = FakeRegisters::kNone;
};

}  // namespace vibid::fw::stm32::test
