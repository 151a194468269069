// A fake STM32F405 register file for host tests of the port's drivers (built with
// VIBID_STM32_FAKE_REGISTERS, see regs/mmio.hpp). Every access is logged in order; registers
// hold what was last written unless a hook models the hardware's reaction (a self-clearing
// bit, a status flag that follows a command). Unwritten registers read as zero.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "regs/core_m4.hpp"
#include "regs/mmio.hpp"

namespace vibid::fw::stm32::test {

struct Access {
  enum class Kind : std::uint8_t { kRead, kWrite, kCpu };
  Kind kind = Kind::kRead;
  Address address = 0;
  std::uint32_t value = 0;  ///< Read or written value (the whole word for 4-byte accesses).
  unsigned width = 4;
  fake::CpuOp op = fake::CpuOp::kDsb;
};

class FakeRegisters {
 public:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  /// Returns the value the register reads as, given what it holds.
  using ReadHook = std::function<std::uint32_t(std::uint32_t held)>;
  /// Returns what the register holds after `written` lands on `held`.
  using WriteHook = std::function<std::uint32_t(std::uint32_t held, std::uint32_t written)>;

  /// The instance the port's Reg() talks to; cleared by every test fixture.
  static FakeRegisters& Get();

  void Clear();
  /// Direct state access for the test: no log, no hooks.
  std::uint32_t Peek(Address word_address) const;
  void Poke(Address word_address, std::uint32_t value);
  void OnRead(Address word_address, ReadHook hook) { read_hooks_[word_address] = std::move(hook); }
  void OnWrite(Address word_address, WriteHook hook) {
    write_hooks_[word_address] = std::move(hook);
  }

  /// Long polls would fill the log with reads: a test can keep only writes and CPU operations.
  void LogReads(bool on) { log_reads_ = on; }
  const std::vector<Access>& log() const { return log_; }
  /// Values written to `address`, in order.
  std::vector<std::uint32_t> WritesTo(Address address) const;
  /// Index in Log() of the first write of exactly `value` to `address` at or after `from`.
  std::size_t FindWrite(Address address, std::uint32_t value, std::size_t from = 0) const;
  /// Index of the first write to `address` with all of `bits` set, at or after `from`.
  std::size_t FindWriteWithBits(Address address, std::uint32_t bits, std::size_t from = 0) const;
  /// Index of the first CPU operation `op` at or after `from`.
  std::size_t FindCpu(fake::CpuOp op, std::size_t from = 0) const;
  std::size_t CountWrites(Address address) const { return WritesTo(address).size(); }

  /// Runs `f`; true when it ended in fake::Halt (where the target stops for good: SystemReset
  /// after its AIRCR write), false when it returned.
  static bool RunUntilHalt(const std::function<void()>& f);
  [[noreturn]] static void Halt();

  // Called through fake::Read/Write/Cpu.
  std::uint32_t Read(Address address, unsigned width);
  void Write(Address address, std::uint32_t value, unsigned width);
  void Cpu(fake::CpuOp op);

 private:
  std::map<Address, std::uint32_t> words_;
  std::map<Address, ReadHook> read_hooks_;
  std::map<Address, WriteHook> write_hooks_;
  std::vector<Access> log_;
  bool log_reads_ = true;
};

}  // namespace vibid::fw::stm32::test
