#include "board_watch.hpp"

#include <chrono>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "bindings.hpp"

namespace vibid::python {

BoardWatch::BoardWatch(device::Connection& c, workflow::WatchBoardSettings settings,
                       const std::string& journal)
    : run_(std::move(settings)), journal_(journal, "journal") {
  thread_ = std::thread([this, &c] {
    workflow::WatchBoardEvents events;
    events.starting = [this](const workflow::WatchBoardStart& s) {
      const nlohmann::json j = {{"responses", s.responses},
                                {"log_rate_hz", s.log_rate_hz},
                                {"board_columns", s.board_columns},
                                {"model_stale", s.model_stale},
                                {"model_text", s.model_text}};
      Push({"start", j.dump(), ""});
    };
    events.reference = [this](const workflow::WatchSession& s) {
      Push({"reference", workflow::WatchReferenceJson(s.reference()).dump(), ""});
    };
    events.header = [this](const std::string& line) { Push({"header", line, ""}); };
    events.block = [this](const workflow::WatchBlock& b, const std::string& line) {
      Push({"block", line, workflow::WatchBlockText(b)});
    };
    try {
      const workflow::WatchBoardResult r =
          run_.Run(c, journal_, events, [this] { return stop_.load(); });
      const nlohmann::json j = {{"stopped", r.stopped},
                                {"warning", r.warning},
                                {"model_stale", r.model_stale},
                                {"model_text", r.model_text},
                                {"model_before", r.model_before},
                                {"reference_built", r.reference_built},
                                {"reference_left_s", r.reference_left_s},
                                {"blocks", r.blocks},
                                {"log_rate_hz", r.log_rate_hz}};
      std::lock_guard lock(mutex_);
      result_ = j.dump();
    } catch (...) {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
    }
    std::lock_guard lock(mutex_);
    done_ = true;
    ready_.notify_one();
  });
}

BoardWatch::~BoardWatch() {
  stop_ = true;  // the runner stops the board at its next report
  if (thread_.joinable()) thread_.join();
}

void BoardWatch::Push(Item item) {
  std::lock_guard lock(mutex_);
  items_.push_back(std::move(item));
  ready_.notify_one();
}

py::tuple BoardWatch::Next(double timeout_s) {
  std::optional<Item> item;
  bool end = false;
  {
    py::gil_scoped_release release;
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                    [this] { return !items_.empty() || done_; });
    if (!items_.empty()) {
      item = std::move(items_.front());
      items_.pop_front();
    } else {
      end = done_;
    }
  }
  if (item) {
    if (item->kind == "block") return py::make_tuple("block", item->a, item->b);
    return py::make_tuple(item->kind, ToPython(nlohmann::json::parse(item->a)));
  }
  if (!end) return py::make_tuple("wait");
  {
    py::gil_scoped_release release;
    if (thread_.joinable()) thread_.join();
  }
  if (error_) std::rethrow_exception(error_);
  return py::make_tuple("end", ToPython(nlohmann::json::parse(result_)));
}

}  // namespace vibid::python
