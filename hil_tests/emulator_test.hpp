// Base of the hil tests that reach past the board's protocol into the emulator behind the target
// (its flash file, its USB/IP device): on any other target they skip, saying what they need.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "target.hpp"

namespace vibid::hil {

class EmulatorTest : public ::testing::Test {
 protected:
  /// `needs`: what the test needs of the emulator, for the skip message ("has no flash file...").
  explicit EmulatorTest(const char* needs) : needs_(needs) {}

  void SetUp() final {
    target = MakeTarget();
    emu = target->emulator();
    if (emu == nullptr) GTEST_SKIP() << "target '" << target->Name() << "' " << needs_;
    SetUpEmulator();
  }

  /// What the test sets up once it has the emulator.
  virtual void SetUpEmulator() {}

  std::unique_ptr<Target> target;
  EmulatorProcess* emu = nullptr;

 private:
  const char* needs_;
};

}  // namespace vibid::hil
