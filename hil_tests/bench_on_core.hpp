// Test support for the bench's route tests: a bench served in-process on the firmware core
// (hil::CoreLoopback), the way the route tests drive it: the board, the server with the routes a
// test adds, a second connection that probes the board behind the bench's back, and a scratch
// folder for the bench's files. It lives beside the core loopback it wraps, above the bench it
// serves.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <httplib.h>

#include "core_loopback.hpp"
#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/live_hub.hpp"
#include "vibid/bench/server.hpp"

namespace vibid::bench::testing {

class BenchOnCore : public ::testing::Test {
 protected:
  /// Opens the board and the probe, lets `add_routes` add the view's routes to server_ (with
  /// board_, hub_ and dir_ set), then starts serving.
  void StartBench(const std::string& tag, const std::function<void()>& add_routes) {
    dir_ = std::filesystem::temp_directory_path() /
           ("vibid-" + tag + "-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    connection_ = std::make_unique<device::Connection>(core_.Connect());
    probe_ = std::make_unique<device::Connection>(core_.Connect());
    board_ = std::make_unique<BenchBoard>(*connection_, dir_.string(), hub_);
    server_ = std::make_unique<BenchServer>(*board_, hub_, ServerOptions{});
    add_routes();
    server_->Start();
  }
  void TearDown() override {
    if (board_) board_->Shutdown();
    server_.reset();
    board_.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  /// POST /api/`route` with the page's token.
  httplib::Result Post(const std::string& route, const std::string& body) {
    httplib::Client c("127.0.0.1", server_->port());
    c.set_read_timeout(10, 0);
    return c.Post("/api/" + route, {{kTokenHeader, server_->token()}}, body, "application/json");
  }

  /// Files and folders the bench's directory holds.
  std::size_t Entries() const {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir_)) ++n;
    return n;
  }

  hil::CoreLoopback core_;
  LiveHub hub_;
  std::filesystem::path dir_;
  std::unique_ptr<device::Connection> connection_;
  std::unique_ptr<device::Connection> probe_;
  std::unique_ptr<BenchBoard> board_;
  std::unique_ptr<BenchServer> server_;
};

}  // namespace vibid::bench::testing
