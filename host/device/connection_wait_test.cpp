// How long the host waits for an answer: a self-test check that takes its full measuring time
// (wire::kSelfTestLongestCheckMs) is answered to the first request, never sent again (a second
// request would make the board measure twice); any other request is retried after the usual
// timeout. A scripted device answers every request after a set delay and counts the requests.
#include <atomic>
#include <chrono>
#include <deque>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "vibid/device/connection.hpp"
#include "vibid/device/error.hpp"

namespace vibid::device {
namespace {

using namespace std::chrono_literals;

class SlowDevice : public Transport {
 public:
  struct Shared {
    std::mutex mutex;
    std::deque<std::pair<std::chrono::steady_clock::time_point, wire::Report>> pending;
    int self_test_requests = 0;
    std::chrono::milliseconds self_test_delay{0};
  };
  explicit SlowDevice(Shared& shared) : s_(shared) {}

  void Send(const wire::Report& request) override {
    wire::Header h;
    ASSERT_EQ(wire::DecodeHeader(request, h), Status::kOk);
    std::lock_guard lock(s_.mutex);
    wire::Report answer{};
    auto due = std::chrono::steady_clock::now();
    const auto command = static_cast<wire::Command>(h.command);
    if (command == wire::Command::kGetInfo) {
      ASSERT_EQ(wire::BuildReport(command, h.token, 0, wire::kFlagResponse, Status::kOk, wire::InfoResponse{},
                                  answer),
                Status::kOk);
    } else {
      ASSERT_EQ(command, wire::Command::kSelfTest);
      ++s_.self_test_requests;
      wire::SelfTestResponse r;
      r.verdict = wire::SelfTestVerdict::kPass;
      ASSERT_EQ(wire::BuildReport(command, h.token, 0, wire::kFlagResponse, Status::kOk, r, answer),
                Status::kOk);
      due += s_.self_test_delay;
    }
    s_.pending.emplace_back(due, answer);
  }

  std::size_t Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                      std::chrono::milliseconds timeout) override {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      {
        std::lock_guard lock(s_.mutex);
        if (!s_.pending.empty() && s_.pending.front().first <= std::chrono::steady_clock::now()) {
          std::copy(s_.pending.front().second.begin(), s_.pending.front().second.end(),
                    out.begin());
          s_.pending.pop_front();
          return wire::kReportBytes;
        }
      }
      std::this_thread::sleep_for(2ms);
    }
    return 0;
  }

  std::string Describe() const override { return "slow test device"; }

 private:
  Shared& s_;
};

TEST(ConnectionWait, ASelfTestCheckThatMeasuresItsFullTimeIsAskedOnce) {
  SlowDevice::Shared shared;
  ConnectionOptions options;
  options.timeout = 200ms;  // the usual answer timeout, shortened to keep the test short
  Connection c(std::make_unique<SlowDevice>(shared), options);
  // The board's longest check: more than the usual timeout, within timeout + the longest check.
  shared.self_test_delay = std::chrono::milliseconds{wire::kSelfTestLongestCheckMs};
  EXPECT_EQ(c.SelfTest(0).verdict, wire::SelfTestVerdict::kPass);
  EXPECT_EQ(shared.self_test_requests, 1);
  EXPECT_EQ(c.counters().retries, 0u);
}

TEST(ConnectionWait, ASelfTestBeyondItsLongestTimeIsRetriedThenFails) {
  SlowDevice::Shared shared;
  ConnectionOptions options;
  options.timeout = 50ms;
  options.retries = 1;
  Connection c(std::make_unique<SlowDevice>(shared), options);
  // Longer than timeout + the longest check on every try: two requests, then the error.
  shared.self_test_delay = std::chrono::milliseconds{3 * wire::kSelfTestLongestCheckMs};
  EXPECT_THROW((void)c.SelfTest(0), DeviceError);
  EXPECT_EQ(shared.self_test_requests, 2);
}

}  // namespace
}  // namespace vibid::device
