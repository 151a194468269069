#include "target.hpp"

#include <cstdlib>
#include <stdexcept>

#include "vibid/device/hid_transport.hpp"

namespace vibid::hil {
namespace {

class CoreTarget final : public Target {
 public:
  std::string Name() const override { return "core"; }
  std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options) override {
    return std::make_unique<device::Connection>(loopback_.Connect(), options);
  }
  bool Restart() override {
    loopback_.Restart();
    return true;
  }
  CoreLoopback* loopback() override { return &loopback_; }

 private:
  CoreLoopback loopback_;
};

class HidTarget final : public Target {
 public:
  std::string Name() const override { return "hid"; }
  std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options) override {
    return std::make_unique<device::Connection>(device::OpenHid(""), options);
  }
  bool Restart() override { return false; }
};

}  // namespace

std::unique_ptr<Target> MakeTarget() {
  const char* env = std::getenv("VIBID_TARGET");
  const std::string name = env == nullptr ? "" : env;
  if (name.empty() || name == "core") return std::make_unique<CoreTarget>();
  if (name == "hid") return std::make_unique<HidTarget>();
  throw std::invalid_argument("VIBID_TARGET=" + name + ": expected core or hid");
}

}  // namespace vibid::hil
