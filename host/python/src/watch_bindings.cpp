// Output-only modes (oma::SsiCov) for vibid.ssi_cov, and the watch (workflow::WatchSession) for
// vibid.watch: the session fed with responses as numpy arrays, its blocks as the JSON lines
// `vibid watch --json` prints (and their text lines), the columns a recording's watch takes.
// Options are validated by the library, its refusals naming them as Python spells them.
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "board_watch.hpp"
#include "vibid/common/error.hpp"
#include "vibid/oma/ssi_cov.hpp"
#include "vibid/workflow/oma_json.hpp"
#include "vibid/workflow/watch_columns.hpp"
#include "vibid/workflow/watch_session.hpp"

namespace vibid::python {
namespace {

using Signals = py::array_t<double, py::array::c_style>;
using workflow::WatchOptions;
using workflow::WatchSession;

// A (channels, samples) float64 C-ordered array is a column-major (samples, channels) matrix:
// read in place.
Eigen::Map<const Eigen::MatrixXd> SamplesOf(const Signals& a, const char* name) {
  Require(a.ndim() == 2, std::string(name) + " must be 2-D (channels, samples), not " +
                             std::to_string(a.ndim()) + "-D");
  return {a.data(), static_cast<Eigen::Index>(a.shape(1)), static_cast<Eigen::Index>(a.shape(0))};
}

/// Each block as its JSON line and its text line.
std::vector<std::pair<std::string, std::string>> Lines(const std::vector<workflow::WatchBlock>& b) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const workflow::WatchBlock& block : b) {
    out.emplace_back(workflow::WatchBlockJson(block).dump(), workflow::WatchBlockText(block));
  }
  return out;
}

std::unique_ptr<WatchSession> MakeSession(WatchOptions o) {
  o.spelling = workflow::OptionSpelling::kPython;
  return std::make_unique<WatchSession>(o);
}

std::vector<std::pair<std::string, std::string>> Feed(WatchSession& s, const Signals& samples,
                                                      const std::optional<Signals>& board,
                                                      std::optional<double> t_first_s) {
  const Eigen::Map<const Eigen::MatrixXd> y = SamplesOf(samples, "samples");
  std::vector<workflow::WatchBlock> blocks;
  if (board) {
    const Eigen::Map<const Eigen::MatrixXd> b = SamplesOf(*board, "board");
    py::gil_scoped_release release;
    blocks = s.Feed(y, b, t_first_s);
  } else {
    py::gil_scoped_release release;
    blocks = s.Feed(y, t_first_s);
  }
  return Lines(blocks);
}

void SetReference(WatchSession& s, const Signals& reference) {
  const Eigen::Map<const Eigen::MatrixXd> y = SamplesOf(reference, "reference");
  py::gil_scoped_release release;
  s.SetReference(y);
}

py::object Reference(const WatchSession& s) {
  if (!s.has_reference()) return py::none();
  return ToPython(workflow::WatchReferenceJson(s.reference()));
}

py::object Header(const WatchSession& s) {
  if (!s.has_reference()) return py::none();
  return py::str(workflow::WatchHeaderJson(s).dump());
}

py::tuple Columns(const std::vector<std::string>& names, const std::vector<std::string>& requested,
                  const std::string& source) {
  const workflow::WatchColumns c =
      workflow::ChooseWatchColumns(names, requested, source, workflow::OptionSpelling::kPython);
  return py::make_tuple(c.responses, c.board_statistic, c.board_flag);
}

/// SSI-cov of responses (channels, samples): the library's modes and diagram as JSON.
py::object SsiCov(const Signals& responses, const oma::SsiCovOptions& options) {
  const Eigen::Map<const Eigen::MatrixXd> y = SamplesOf(responses, "responses");
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = workflow::SsiCovJson(oma::SsiCov(y, options));
  }
  return ToPython(j);
}

}  // namespace

void RegisterWatch(py::module_& m) {
  py::class_<oma::SsiCovOptions>(m, "_SsiCovOptions")
      .def(py::init<>())
      .def_readwrite("fs_hz", &oma::SsiCovOptions::fs_hz)
      .def_readwrite("fmax_hz", &oma::SsiCovOptions::fmax_hz)
      .def_readwrite("fmin_hz", &oma::SsiCovOptions::fmin_hz)
      .def_readwrite("order_max", &oma::SsiCovOptions::order_max);
  m.def("ssi_cov", &SsiCov, py::arg("responses"), py::arg("options"));
  py::class_<WatchOptions>(m, "_WatchOptions")
      .def(py::init<>())
      .def_readwrite("fs_hz", &WatchOptions::fs_hz)
      .def_readwrite("channels", &WatchOptions::channels)
      .def_readwrite("reference_s", &WatchOptions::reference_s)
      .def_readwrite("block_s", &WatchOptions::block_s)
      .def_readwrite("window_blocks", &WatchOptions::window_blocks)
      .def_readwrite("sequential_blocks", &WatchOptions::sequential_blocks)
      .def_readwrite("false_alarm_per_hour", &WatchOptions::false_alarm_per_hour)
      .def_readwrite("fmax_hz", &WatchOptions::fmax_hz)
      .def_readwrite("modes_s", &WatchOptions::modes_s)
      .def_readwrite("order", &WatchOptions::order)
      .def("window_false_alarm", &WatchOptions::WindowFalseAlarm)
      .def("block_false_alarm", &WatchOptions::BlockFalseAlarm);
  py::class_<WatchSession>(m, "_WatchSession")
      .def(py::init(&MakeSession))
      .def("set_reference", &SetReference)
      .def("feed", &Feed, py::arg("samples"), py::arg("board"), py::arg("t_first_s"))
      .def("gap", &WatchSession::Gap)
      .def("set_board_threshold", &WatchSession::SetBoardThreshold)
      .def_property_readonly("has_reference", &WatchSession::has_reference)
      .def_property_readonly("reference_left_s", &WatchSession::reference_left_s)
      .def("reference", &Reference)
      .def("header", &Header);
  m.def("watch_columns", &Columns);
  py::class_<BoardWatch>(m, "_BoardWatch")
      .def("next", &BoardWatch::Next, py::arg("timeout_s"))
      .def("stop", &BoardWatch::Stop)
      .def_property_readonly("fs_hz", &BoardWatch::FsHz);
}

}  // namespace vibid::python
