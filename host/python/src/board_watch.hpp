// The rig watched on a board from Python (Board.watch): workflow::WatchBoardRun, the runner
// `vibid watch --device` and the bench call, on its own thread; what it says (the start, the
// reference, each block with its JSON line) queued for Python to take as it comes. The board is
// stopped when the watch is stopped or dropped before its end.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>

#include <pybind11/pybind11.h>

#include "vibid/device/connection.hpp"
#include "vibid/workflow/watch_board_run.hpp"

namespace vibid::python {

namespace py = pybind11;

class BoardWatch {
 public:
  /// Checks the settings and creates the journal (InputError naming the option as Python spells
  /// it, before the board is touched), then runs on its own thread.
  BoardWatch(device::Connection& c, workflow::WatchBoardSettings settings,
             const std::string& journal);
  ~BoardWatch();
  BoardWatch(const BoardWatch&) = delete;
  BoardWatch& operator=(const BoardWatch&) = delete;

  /// ("start", dict), ("reference", dict), ("block", json_line, text), ("wait",) when nothing
  /// came within `timeout_s`, ("end", dict) once the run is over and everything was taken; the
  /// run's error is raised then.
  py::tuple Next(double timeout_s);
  void Stop() { stop_ = true; }
  double FsHz() const { return run_.options().fs_hz; }

 private:
  struct Item {
    std::string kind;
    std::string a;
    std::string b;
  };
  void Push(Item item);

  workflow::WatchBoardRun run_;
  workflow::WatchJournal journal_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Item> items_;
  bool done_ = false;
  std::string result_;  // the run's result as JSON, once done
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace vibid::python
