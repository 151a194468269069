// The board: a device::Connection opened by the same URLs as `--device`, the acquisition planned,
// preflighted and run by the device layer's functions `vibid acquire` calls. Board I/O runs
// without the GIL; Ctrl-C is noticed between reports (the acquisition's stop request) and stops
// the board before KeyboardInterrupt is raised.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "board_watch.hpp"
#include "vibid/common/q31_decimal.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/model/model.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/device/info_json.hpp"
#include "vibid/device/log_facts.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/device/select.hpp"

namespace vibid::python {
namespace {

/// Log records as a recording: (names, data (channels, samples), sample_index), converted through
/// the board's calibration by the device layer (the CSV `vibid acquire` writes holds the same).
py::tuple RecordsTable(const device::LogPull& pull, const wire::CalibrationRecord& record,
                       bool has_record) {
  const device::LogTable table = device::MakeLogTable(pull, record, has_record);
  const auto n = static_cast<py::ssize_t>(pull.records.size());
  const auto k = static_cast<py::ssize_t>(table.columns.size());
  py::array_t<double> data({k, n});
  for (py::ssize_t col = 0; col < k && n > 0; ++col) {
    const Eigen::VectorXd& v = table.columns[static_cast<std::size_t>(col)];
    std::copy(v.data(), v.data() + n, data.mutable_data(col, 0));
  }
  py::array_t<std::uint32_t> index(n);
  for (py::ssize_t i = 0; i < n; ++i)
    index.mutable_data()[i] = pull.records[static_cast<std::size_t>(i)].sample_index;
  return py::make_tuple(table.names, data, index);
}

/// A streamed acquisition running on its own thread: the records come out in blocks as the
/// board's reports arrive (Connection's LiveRecords), and the board is stopped when the stream is
/// stopped or dropped before its end.
class Stream {
 public:
  Stream(device::Connection& c, const wire::AcqConfigureRequest& cfg,
         const wire::CalibrationRecord& record, bool has_record)
      : cfg_(cfg), record_(record), has_record_(has_record) {
    thread_ = std::thread([this, &c] {
      try {
        device::LogPull pull = c.AcquireStreamed(
            {}, [this](const wire::LogTrailer*) { return stop_.load(); },
            [this](std::uint32_t first, std::span<const wire::LogRecord> records) {
              std::lock_guard lock(mutex_);
              blocks_.emplace_back(first,
                                   std::vector<wire::LogRecord>(records.begin(), records.end()));
              ready_.notify_one();
            });
        std::lock_guard lock(mutex_);
        pull_ = std::move(pull);
      } catch (...) {
        try {
          c.StopAcquisition();  // the board is left idle whenever it can still be reached
        } catch (const device::DeviceError&) {
        }
        std::lock_guard lock(mutex_);
        error_ = std::current_exception();
      }
      std::lock_guard lock(mutex_);
      done_ = true;
      ready_.notify_one();
    });
  }

  ~Stream() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  /// ("block", first log index, names, data, sample_index), ("wait",) when nothing came within
  /// `timeout_s`, ("end",) when the acquisition is over and every block was taken.
  py::tuple Next(double timeout_s) {
    std::optional<std::pair<std::uint32_t, std::vector<wire::LogRecord>>> block;
    bool end = false;
    {
      py::gil_scoped_release release;
      std::unique_lock lock(mutex_);
      ready_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                      [this] { return !blocks_.empty() || done_; });
      if (!blocks_.empty()) {
        block = std::move(blocks_.front());
        blocks_.pop_front();
      } else {
        end = done_;
      }
    }
    if (!block) return end ? py::make_tuple("end") : py::make_tuple("wait");
    device::LogPull pull = Shape();
    pull.records = std::move(block->second);
    const py::tuple t = RecordsTable(pull, record_, has_record_);
    return py::make_tuple("block", block->first, t[0], t[1], t[2]);
  }

  void Stop() { stop_ = true; }

  double FsHz() const { return 1e6 / cfg_.sample_period_us / cfg_.decimation; }

  /// Waits for the end; rethrows the acquisition's error; returns the records of the final pull
  /// from log index `next` on (those no block delivered) and whether it was stopped.
  py::tuple Finish(std::uint32_t next) {
    {
      py::gil_scoped_release release;
      if (thread_.joinable()) thread_.join();
    }
    if (error_) std::rethrow_exception(error_);
    device::LogPull rest = Shape();
    rest.first_record = next;
    for (std::size_t i = 0; i < pull_.records.size(); ++i) {
      if (pull_.first_record + i >= next) rest.records.push_back(pull_.records[i]);
    }
    const py::tuple t = RecordsTable(rest, record_, has_record_);
    return py::make_tuple(t[0], t[1], t[2], pull_.stopped);
  }

 private:
  /// An empty pull of the configured acquisition (layout, period, decimation) for its records.
  device::LogPull Shape() const {
    device::LogPull p;
    p.layout = wire::LogLayout{cfg_.channel_mask, cfg_.flags};
    p.trailer.sample_period_us = cfg_.sample_period_us;
    p.trailer.decimation = cfg_.decimation;
    return p;
  }

  wire::AcqConfigureRequest cfg_;
  wire::CalibrationRecord record_;
  bool has_record_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::pair<std::uint32_t, std::vector<wire::LogRecord>>> blocks_;
  bool done_ = false;
  std::exception_ptr error_;
  device::LogPull pull_;
  std::thread thread_;
};

class Board {
 public:
  explicit Board(const std::string& url) {
    const device::DeviceChoice choice = device::ChooseDevice(url);
    const device::DeviceSpec spec = device::ParseDeviceSpec(choice.text, choice.origin);
    py::gil_scoped_release release;
    connection_ = std::make_unique<device::Connection>(device::OpenTransport(spec));
  }

  device::Connection& c() {
    if (!connection_) throw device::DeviceError("the board is closed");
    return *connection_;
  }

  std::string Describe() { return c().Describe(); }

  py::object Info() {
    nlohmann::json j;
    {
      py::gil_scoped_release release;
      device::Connection& con = c();
      const wire::InfoResponse info = con.GetInfo();
      j = device::InfoJson(con, info, con.GetClips(), con.GetSamplingInfo(), con.GetHealthInfo());
    }
    return ToPython(j);
  }

  std::string State() {
    wire::StatusResponse st;
    {
      py::gil_scoped_release release;
      st = c().GetStatus();
    }
    switch (st.acq_state) {
      case wire::AcqState::kIdle: return "idle";
      case wire::AcqState::kArmed: return "armed";
      case wire::AcqState::kAcquiring: return "acquiring";
      case wire::AcqState::kDone: return "done";
    }
    return "unknown";
  }

  /// (names, data (channels, samples), fs_hz, sample_index, sample instants {column: us},
  /// end, the recording's facts as its sidecar's JSON text), `end` "" for an acquisition that ran
  /// its length, else why it ended early: "interrupted" (Ctrl-C), "trigger-timeout: MESSAGE",
  /// "incomplete: MESSAGE" (the log wrapped, or the pull gave up) or "lost: MESSAGE" (the board
  /// failed or went away: the records that had arrived); the records kept are returned in every
  /// case.
  py::tuple Acquire(const device::AcquireSettings& settings, const std::string& scenario,
                    const std::vector<float>& scenario_params) {
    device::Trigger trig;
    wire::AcqConfigureRequest cfg = device::PlanAcquisition(settings, trig);
    Require(scenario_params.size() <= 4, "--scenario-param takes at most 4 values");
    bool interrupted = false;
    bool timed_out = false;
    std::string incomplete;
    std::string lost;
    device::LogPull pull;
    wire::CalibrationRecord record;
    bool has_record = false;
    std::optional<wire::SamplingInfoResponse> instants;
    // What the recording's sidecar states (log_facts.hpp), as `vibid acquire` writes it.
    ident::AcquisitionFacts asked;
    asked.seconds = settings.seconds;
    asked.trigger = settings.trigger;
    asked.pretrigger_s = settings.pretrigger_s;
    asked.scenario = scenario;
    for (float p : scenario_params) asked.scenario_params.push_back(ShortestFloat32Decimal(p));
    const std::string start_timestamp = ident::UtcTimestampNow();
    device::BoardContext board;
    {
      py::gil_scoped_release release;
      device::Connection& con = c();
      record = device::ActiveRecord(con, has_record);
      device::ApplyCalibration(record, has_record, con.GetStatus().dob_running != 0,
                               settings.no_dob, trig, cfg);
      device::Preflight(con.info(), cfg, settings);
      cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagStream);
      if (!scenario.empty()) con.SelectScenario(scenario, scenario_params);
      con.Configure(cfg);
      const auto started = std::chrono::steady_clock::now();
      // Asked at least every 100 ms while the board samples: a pending Ctrl-C stops it, and so
      // does a trigger that has not fired within the timeout.
      const device::StopRequest stop = [&](const wire::LogTrailer* state) {
        {
          py::gil_scoped_acquire acquire;
          if (PyErr_CheckSignals() != 0) {
            PyErr_Clear();
            interrupted = true;
          }
        }
        if (!interrupted && settings.trigger_timeout_s > 0.0 && state != nullptr &&
            state->acq_state == wire::AcqState::kArmed &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() >=
                settings.trigger_timeout_s)
          timed_out = true;
        return interrupted || timed_out;
      };
      // The records as they arrive, each log index once: what is kept when the board fails
      // before the pull's own record is complete.
      std::vector<wire::LogRecord> arrived;
      const device::LiveRecords live = [&](std::uint32_t first,
                                           std::span<const wire::LogRecord> records) {
        for (std::size_t i = 0; i < records.size(); ++i) {
          if (first + i == arrived.size()) arrived.push_back(records[i]);
        }
      };
      try {
        pull = con.AcquireStreamed({}, stop, live);
      } catch (const device::IncompleteLog& e) {
        // The log wrapped over records before they could be pulled: the rest is returned.
        pull = e.pull();
        incomplete = e.what();
      } catch (const device::Interrupted&) {
        throw;
      } catch (const device::DeviceError& e) {
        // The board failed or went away: the records that arrived are returned with the error.
        try {
          con.StopAcquisition();
        } catch (const device::DeviceError&) {
        }
        pull = device::LogPull{};
        pull.layout = wire::LogLayout{cfg.channel_mask, cfg.flags};
        pull.trailer.sample_period_us = cfg.sample_period_us;
        pull.trailer.decimation = cfg.decimation;
        pull.records = std::move(arrived);
        lost = e.what();
      } catch (...) {
        // The board is left idle whenever it can still be reached.
        try {
          con.StopAcquisition();
        } catch (const device::DeviceError&) {
        }
        throw;
      }
      if (lost.empty()) {
        try {
          board = device::ContextOf(con);
          instants = board.instants;
        } catch (const device::DeviceError&) {
        }
      }
    }
    const std::string facts = ident::FormatRecordingFacts(device::LogFacts(
        pull, pull.records.size(), record, has_record, board, asked, start_timestamp));
    const py::tuple t = RecordsTable(pull, record, has_record);
    const double fs_hz = 1e6 / cfg.sample_period_us / cfg.decimation;
    py::dict instants_us;
    if (instants) {
      const device::LogTable table = device::MakeLogTable(pull, record, has_record);
      for (const auto& [name, us] : device::SampleInstantsUs(table, pull, *instants))
        instants_us[py::str(name)] = us;
    }
    std::string end;
    if (!lost.empty())
      end = "lost: " + lost;
    else if (!incomplete.empty())
      end = "incomplete: " + incomplete;
    else if (interrupted)
      end = "interrupted";
    else if (timed_out)
      end = "trigger-timeout: the trigger did not fire within " +
            py::str(py::float_(settings.trigger_timeout_s)).cast<std::string>() +
            " s (trigger_timeout_s)";
    return py::make_tuple(t[0], t[1], fs_hz, t[2], instants_us, end, facts);
  }

  /// Builds the record from the model, the observer design (the JSON of dob_design) and the
  /// sensors (a sensors file's JSON; None: the scaling the board holds) and stages it
  /// (`vibid cal upload`). Returns the label and the stored record's CRC.
  py::dict CalUpload(const model::Model& m, const py::handle& design, const py::handle& sensors,
                     const std::string& label) {
    device::RecordInputs in;
    in.model = m;
    in.observer = dob::ObserverFromJson(FromPython(design, "design"), "design").description;
    in.label = label;
    in.created_unix_s = std::chrono::duration_cast<std::chrono::seconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count();
    unsigned major = 0, minor = 0, patch = 0;
    static_cast<void>(std::sscanf(VIBID_VERSION, "%u.%u.%u", &major, &minor, &patch));
    in.host_major = static_cast<std::uint8_t>(major);
    in.host_minor = static_cast<std::uint8_t>(minor);
    in.host_patch = static_cast<std::uint16_t>(patch);
    if (!sensors.is_none())
      in.sensors = device::SensorsFromJson(FromPython(sensors, "sensors"), "sensors");
    std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
    {
      py::gil_scoped_release release;
      device::Connection& con = c();
      if (sensors.is_none()) {
        bool has_record = false;
        const wire::CalibrationRecord old = device::ActiveRecord(con, has_record);
        device::KeepBoardSensors(in, has_record ? &old : nullptr);
      }
      wire::EncodeCalibrationRecord(device::BuildCalibrationRecord(in), bytes);
      con.CalPut(bytes);
    }
    py::dict d;
    d["label"] = in.label;
    d["bytes"] = bytes.size();
    d["crc"] = wire::StoredRecordCrc(bytes);
    return d;
  }

  /// Plans, preflights and configures the acquisition as Acquire does, then starts it on its own
  /// thread; the Stream hands out its records as they arrive.
  std::unique_ptr<Stream> StreamStart(const device::AcquireSettings& settings,
                                      const std::string& scenario,
                                      const std::vector<float>& scenario_params) {
    device::Trigger trig;
    wire::AcqConfigureRequest cfg = device::PlanAcquisition(settings, trig);
    Require(scenario_params.size() <= 4, "--scenario-param takes at most 4 values");
    py::gil_scoped_release release;
    device::Connection& con = c();
    bool has_record = false;
    const wire::CalibrationRecord record = device::ActiveRecord(con, has_record);
    device::ApplyCalibration(record, has_record, con.GetStatus().dob_running != 0, settings.no_dob,
                             trig, cfg);
    device::Preflight(con.info(), cfg, settings);
    cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagStream);
    if (!scenario.empty()) con.SelectScenario(scenario, scenario_params);
    con.Configure(cfg);
    return std::make_unique<Stream>(con, cfg, record, has_record);
  }

  py::dict CalCommit() {
    wire::CalCommitResponse r;
    {
      py::gil_scoped_release release;
      r = c().CalCommit();
    }
    py::dict d;
    d["slot"] = static_cast<int>(r.slot);
    d["sequence"] = r.sequence;
    return d;
  }

  void Dob(bool run) {
    py::gil_scoped_release release;
    c().DobControl(run);
  }

  void Close() {
    py::gil_scoped_release release;
    connection_.reset();
  }

 private:
  std::unique_ptr<device::Connection> connection_;
};

}  // namespace

void RegisterBoard(py::module_& m) {
  py::class_<device::AcquireSettings>(m, "_AcquireSettings")
      .def(py::init<>())
      .def_readwrite("seconds", &device::AcquireSettings::seconds)
      .def_readwrite("rate_hz", &device::AcquireSettings::rate_hz)
      .def_readwrite("log_rate_hz", &device::AcquireSettings::log_rate_hz)
      .def_readwrite("decimation", &device::AcquireSettings::decimation)
      .def_readwrite("channels", &device::AcquireSettings::channels)
      .def_readwrite("trigger", &device::AcquireSettings::trigger)
      .def_readwrite("pretrigger_s", &device::AcquireSettings::pretrigger_s)
      .def_readwrite("trigger_timeout_s", &device::AcquireSettings::trigger_timeout_s)
      .def_readwrite("no_dob", &device::AcquireSettings::no_dob)
      .def_readwrite("allow_drops", &device::AcquireSettings::allow_drops);
  py::class_<Stream>(m, "_Stream")
      .def("next", &Stream::Next, py::arg("timeout_s"))
      .def("stop", &Stream::Stop)
      .def_property_readonly("fs_hz", &Stream::FsHz)
      .def("finish", &Stream::Finish, py::arg("next"));
  py::class_<Board>(m, "_Board")
      .def("stream_start", &Board::StreamStart, py::arg("settings"), py::arg("scenario"),
           py::arg("scenario_params"), py::keep_alive<0, 1>())
      .def(py::init<const std::string&>(), py::arg("url"))
      .def("describe", &Board::Describe)
      .def("info", &Board::Info)
      .def("state", &Board::State)
      .def("acquire", &Board::Acquire, py::arg("settings"), py::arg("scenario"),
           py::arg("scenario_params"))
      .def("cal_upload", &Board::CalUpload, py::arg("model"), py::arg("design"), py::arg("sensors"),
           py::arg("label"))
      .def(
          "watch_start",
          [](Board& b, const device::AcquireSettings& acquire, const std::string& scenario,
             const std::vector<float>& scenario_params, const std::vector<std::string>& responses,
             const std::string& reference, const workflow::WatchOptions& options,
             const std::string& journal) {
            workflow::WatchBoardSettings s;
            s.acquire = acquire;
            s.scenario = scenario;
            s.scenario_params = scenario_params;
            s.responses = responses;
            s.reference = reference;
            s.watch = options;
            s.watch.spelling = workflow::OptionSpelling::kPython;
            return std::make_unique<BoardWatch>(b.c(), std::move(s), journal);
          },
          py::arg("settings"), py::arg("scenario"), py::arg("scenario_params"),
          py::arg("responses"), py::arg("reference"), py::arg("options"), py::arg("journal"),
          py::keep_alive<0, 1>())
      .def("cal_commit", &Board::CalCommit)
      .def("dob", &Board::Dob, py::arg("run"))
      .def("close", &Board::Close);
  m.def("label_from_model_path", &device::LabelFromModelPath, py::arg("path"));
  m.def("list_devices", [] {
    std::vector<std::pair<std::string, std::string>> out;
    for (const device::Listing& l : device::ListDevices()) out.emplace_back(l.spec, l.description);
    return out;
  });
}

}  // namespace vibid::python
