#include "fake_registers.hpp"

#include <csetjmp>
#include <cstdlib>

namespace vibid::fw::stm32 {

namespace fake {
std::uint32_t Read(Address address, unsigned width_bytes) {
  return test::FakeRegisters::Get().Read(address, width_bytes);
}
void Write(Address address, std::uint32_t value, unsigned width_bytes) {
  test::FakeRegisters::Get().Write(address, value, width_bytes);
}
void Cpu(CpuOp op) { test::FakeRegisters::Get().Cpu(op); }
void Halt() { test::FakeRegisters::Get().Halt(); }
}  // namespace fake

namespace test {

FakeRegisters& FakeRegisters::Get() {
  static FakeRegisters registers;
  return registers;
}

void FakeRegisters::Clear() {
  log_reads_ = true;
  words_.clear();
  read_hooks_.clear();
  write_hooks_.clear();
  log_.clear();
}

std::uint32_t FakeRegisters::Peek(Address word_address) const {
  const auto it = words_.find(word_address);
  return it == words_.end() ? 0 : it->second;
}

void FakeRegisters::Poke(Address word_address, std::uint32_t value) {
  words_[word_address] = value;
}

std::uint32_t FakeRegisters::Read(Address address, unsigned width) {
  const Address word_address = address & ~Address{3};
  std::uint32_t value = Peek(word_address);
  if (const auto hook = read_hooks_.find(word_address); hook != read_hooks_.end())
    value = hook->second(value);
  if (width == 1) value = (value >> (8 * (address & 3))) & 0xFF;
  if (log_reads_) log_.push_back(Access{Access::Kind::kRead, address, value, width, {}});
  return value;
}

void FakeRegisters::Write(Address address, std::uint32_t value, unsigned width) {
  const Address word_address = address & ~Address{3};
  const std::uint32_t held = Peek(word_address);
  std::uint32_t written = value;
  if (width == 1) {
    const unsigned shift = 8 * static_cast<unsigned>(address & 3);
    written = (held & ~(0xFFU << shift)) | ((value & 0xFF) << shift);
  }
  log_.push_back(Access{Access::Kind::kWrite, address, value, width, {}});
  const auto hook = write_hooks_.find(word_address);
  words_[word_address] = hook != write_hooks_.end() ? hook->second(held, written) : written;
}

namespace {
// The test builds without exceptions (the core's embedded rules): a halt jumps back to
// RunUntilHalt. The frames skipped (SystemReset and its callers) hold nothing to destroy.
std::jmp_buf g_halt_target;
bool g_halt_armed = false;
}  // namespace

bool FakeRegisters::RunUntilHalt(const std::function<void()>& f) {
  g_halt_armed = true;
  if (setjmp(g_halt_target) != 0) {
    g_halt_armed = false;
    return true;
  }
  f();
  g_halt_armed = false;
  return false;
}

void FakeRegisters::Halt() {
  if (!g_halt_armed) std::abort();  // A reset outside RunUntilHalt: the test is wrong.
  std::longjmp(g_halt_target, 1);
}

void FakeRegisters::Cpu(fake::CpuOp op) { log_.push_back(Access{Access::Kind::kCpu, 0, 0, 0, op}); }

std::vector<std::uint32_t> FakeRegisters::WritesTo(Address address) const {
  std::vector<std::uint32_t> out;
  for (const Access& a : log_) {
    if (a.kind == Access::Kind::kWrite && a.address == address) out.push_back(a.value);
  }
  return out;
}

std::size_t FakeRegisters::FindWrite(Address address, std::uint32_t value, std::size_t from) const {
  for (std::size_t i = from; i < log_.size(); ++i) {
    const Access& a = log_[i];
    if (a.kind == Access::Kind::kWrite && a.address == address && a.value == value) return i;
  }
  return kNone;
}

std::size_t FakeRegisters::FindWriteWithBits(Address address, std::uint32_t bits,
                                             std::size_t from) const {
  for (std::size_t i = from; i < log_.size(); ++i) {
    const Access& a = log_[i];
    if (a.kind == Access::Kind::kWrite && a.address == address && (a.value & bits) == bits)
      return i;
  }
  return kNone;
}

std::size_t FakeRegisters::FindCpu(fake::CpuOp op, std::size_t from) const {
  for (std::size_t i = from; i < log_.size(); ++i) {
    if (log_[i].kind == Access::Kind::kCpu && log_[i].op == op) return i;
  }
  return kNone;
}

}  // namespace test
}  // namespace vibid::fw::stm32
