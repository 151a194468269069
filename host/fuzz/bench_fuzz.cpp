// Fuzzes the live bench's request handling: the head checks the connections pass first
// (ParseRequestHead), the HTTP library's parsing behind them, the gate and every route of the
// bench (board, acquisition, calibration, identify and design, hammer test, watch) against the
// firmware core in process (hil CoreLoopback), through BenchServer::Exchange: the bytes a
// connection would deliver, the bytes it would answer. The first byte picks the form of the rest:
//   even: the rest is the request as it arrives (any bytes);
//   odd:  a well-formed request is built: the last bytes pick (from the end) the route, the
//         method, whether the token is sent, a foreign Origin, a foreign Host, the body's
//         Content-Type (application/json as the page sends it, or one that only begins so), a
//         Range header, and the bytes before them are the JSON body (or the query of a GET).
// What every answer must be: one HTTP/1.1 status line with a status the bench answers with
// (never 500: an error no route expected), each security header exactly once, no exception text
// in a header, a Content-Length equal to the body's. A request without the token (or with a
// foreign Host or Origin) is never answered 2xx beyond the page's static files, and leaves the
// board's status and calibration as they were; a type other than application/json is never
// read (never 2xx on a POST). No input replaces the recording kept in the directory (an output
// never replaces a recording). Any acquisition an input starts is stopped and its thread joined
// before the next input.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include "core_loopback.hpp"
#include "fuzz_support.hpp"
#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/calibration_routes.hpp"
#include "vibid/bench/hammer_routes.hpp"
#include "vibid/bench/identify_routes.hpp"
#include "vibid/bench/request_head.hpp"
#include "vibid/bench/server.hpp"
#include "vibid/bench/watch_routes.hpp"

namespace {

using namespace vibid;
using fuzz::Require;

constexpr int kPort = 8080;
const std::string kToken = "00112233445566778899aabbccddeeff";

// A 2-mass chain, so that the calibration, identify and design routes have a model to read.
constexpr const char* kModel = R"({"topology": "chain", "masses": [2.0, 1.5],
  "springs": [4000.0, 3000.0], "dampers": [6.0, 4.5]})";
// A recording in the directory (as the bench writes one): no input may replace it.
constexpr const char* kRecording = "t_s,force1_counts,acc1_counts\n0,1,2\n0.001,3,4\n";

struct Bench {
  hil::CoreLoopback core;
  std::unique_ptr<device::Connection> connection;
  std::unique_ptr<device::Connection> probe;
  bench::LiveHub hub;
  std::string dir;
  std::unique_ptr<bench::BenchBoard> board;
  std::unique_ptr<bench::BenchServer> server;
  std::shared_ptr<bench::HammerTests> hammer;
  std::shared_ptr<bench::WatchRuns> watch;
  std::set<std::string> inputs;  // the directory's files that stay between inputs

  Bench() {
    dir =
        std::filesystem::temp_directory_path() / ("vibid-bench-fuzz-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    connection = std::make_unique<device::Connection>(core.Connect());
    probe = std::make_unique<device::Connection>(core.Connect());
    board = std::make_unique<bench::BenchBoard>(*connection, dir, hub);
    server = std::make_unique<bench::BenchServer>(
        *board, hub, bench::ServerOptions{.bind = "127.0.0.1", .port = kPort, .token = kToken});
    bench::AddCalibrationRoutes(*server, *board, dir, "0.1.0");
    bench::AddIdentifyRoutes(*server, *board, dir);
    hammer = bench::AddHammerRoutes(*server, *board, hub, dir);
    watch = bench::AddWatchRoutes(*server, *board, hub, dir);
    server->StartWithoutSocket(kPort);
    std::ofstream(dir + "/m.json") << kModel;
    std::ofstream(dir + "/bench-20261207T023741Z.csv") << kRecording;
    inputs = {"m.json", "bench-20261207T023741Z.csv"};
  }

  std::string Recording() const {
    std::ifstream f(dir + "/bench-20261207T023741Z.csv", std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  }

  /// What a refused request must not change.
  std::string Facts() {
    const wire::StatusResponse st = probe->GetStatus();
    const wire::InfoResponse info = probe->GetInfo();
    return std::to_string(static_cast<int>(st.acq_state)) + "/" + std::to_string(st.dob_running) +
           "/" + std::to_string(st.cal_sequence) + "/" +
           std::to_string(static_cast<int>(info.cal_state)) + "/" + std::to_string(info.cal_crc);
  }

  /// Ends what an input started: the acquisition stopped and joined, the files it wrote removed.
  void Settle() {
    board->Shutdown();
    Require(Recording() == kRecording);
    std::ofstream(dir + "/m.json") << kModel;  // a design may be written over the model: allowed
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      if (inputs.count(e.path().filename().string()) == 0) std::filesystem::remove_all(e.path());
    }
  }
};

Bench& TheBench() {
  static Bench* b = new Bench;  // lives for the whole run (reachable: not a leak)
  return *b;
}

const char* const kRoutes[] = {
    "/",
    "/assets/bench.js",
    "/views/hammer.js",
    "/api/views",
    "/api/board",
    "/api/state",
    "/api/live",
    "/api/budget",
    "/api/acquire",
    "/api/stop",
    "/api/observer",
    "/api/cal/preview",
    "/api/cal/upload",
    "/api/cal/commit",
    "/api/cal/identify",
    "/api/cal/design",
    "/api/hammer/preflight",
    "/api/hammer/start",
    "/api/hammer/stop",
    "/api/hammer/choose",
    "/api/hammer/save",
    "/api/hammer/snapshot",
    "/api/hammer/traces",
    "/api/watch/start",
    "/api/watch/stop",
    "/api/watch/snapshot",
    "/api/watch/journal",
};

// The body's type: the page's, its spellings the bench reads, and types that only begin so.
const char* const kTypes[] = {
    "application/json",
    "application/json",
    "Application/JSON; charset=utf-8",
    "application/json;charset",
    "application/jsonx",
    "application/json-patch+json",
    "text/plain",
};
const char* const kRanges[] = {"", "", "", "bytes=0-99", "bytes=0-,0-", "bytes=-5", "bytes=9-1"};

struct Built {
  std::string bytes;
  bool authorized = false;  // the token, this bench's Host, no foreign Origin
  bool static_file = false;
  bool json = true;  // the body's type is application/json
};

Built Build(FuzzedDataProvider& in) {
  Built b;
  const std::string path = in.PickValueInArray(kRoutes);
  const bool post = in.ConsumeBool();
  const bool token = in.ConsumeBool();
  const bool foreign_origin = in.ConsumeIntegralInRange<int>(0, 7) == 0;
  const bool foreign_host = in.ConsumeIntegralInRange<int>(0, 7) == 0;
  const std::string type = in.PickValueInArray(kTypes);
  const std::string range = in.PickValueInArray(kRanges);
  const std::string rest = in.ConsumeRemainingBytesAsString();
  const std::string host = (foreign_host ? "evil.example:" : "127.0.0.1:") + std::to_string(kPort);
  std::string target = path;
  if (!post && !rest.empty()) target += "?" + rest;
  b.bytes = std::string(post ? "POST " : "GET ") + target + " HTTP/1.1\r\nHost: " + host + "\r\n";
  if (token) b.bytes += std::string(bench::kTokenHeader) + ": " + kToken + "\r\n";
  b.bytes += std::string("Origin: ") + (foreign_origin ? "http://evil.example" : "http://" + host) +
             "\r\n";
  if (!range.empty()) b.bytes += "Range: " + range + "\r\n";
  if (post) {
    b.bytes += "Content-Type: " + type + "\r\nContent-Length: " + std::to_string(rest.size()) +
               "\r\n\r\n" + rest;
    const std::string media = type.substr(0, type.find(';'));
    b.json = media == "application/json" || media == "Application/JSON";
  } else {
    b.bytes += "\r\n";
  }
  b.authorized = token && !foreign_origin && !foreign_host;
  b.static_file = !post && !foreign_origin && !foreign_host && bench::IsStaticFile("GET", path);
  return b;
}

// `head_request`: the request was HEAD, whose answer states the GET answer's header fields, its
// Content-Length among them, and carries no body (RFC 9110, 9.3.2).
void CheckAnswer(const std::string& answer, bool may_succeed, bool head_request) {
  Require(answer.rfind("HTTP/1.1 ", 0) == 0 && answer.size() >= 12);
  const int status = std::stoi(answer.substr(9, 3));
  static const std::set<int> kKnown = {200, 206, 400, 403, 404, 405, 408, 409, 411,
                                       413, 414, 416, 417, 431, 502, 503, 505};
  Require(kKnown.count(status) == 1);
  Require(may_succeed || status >= 400);
  const std::size_t end = answer.find("\r\n\r\n");
  Require(end != std::string::npos);
  const std::string head = answer.substr(0, end + 2);
  for (const auto& [name, value] : bench::SecurityHeaders()) {
    std::size_t count = 0;
    for (std::size_t p = head.find("\r\n" + name + ": "); p != std::string::npos;
         p = head.find("\r\n" + name + ": ", p + 1))
      ++count;
    Require(count == 1);
  }
  Require(head.find("EXCEPTION_WHAT") == std::string::npos);
  Require(head.find("Access-Control-") == std::string::npos);
  const std::size_t length = head.find("\r\nContent-Length: ");
  if (head_request) {
    Require(answer.size() == end + 4);
  } else if (length != std::string::npos) {
    const std::size_t value = length + 18;
    Require(std::stoul(head.substr(value, head.find("\r\n", value) - value)) ==
            answer.size() - end - 4);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > bench::kMaxHeadBytes + bench::kMaxBodyBytes + 64) return -1;
  if (size == 0) return -1;
  Bench& b = TheBench();
  FuzzedDataProvider in(data + 1, size - 1);
  Built request;
  if ((data[0] & 1) != 0) {
    request = Build(in);
  } else {
    request.bytes = in.ConsumeRemainingBytesAsString();
    // Raw bytes carry the token only if they were built to: then they may succeed.
    request.authorized = request.bytes.find(kToken) != std::string::npos;
    request.static_file = true;
  }
  const std::string before = b.Facts();
  const std::string answer = b.server->Exchange(request.bytes);
  CheckAnswer(answer, (request.authorized && request.json) || request.static_file,
              request.bytes.rfind("HEAD ", 0) == 0);
  if (!request.authorized) Require(b.Facts() == before);
  b.Settle();
  return 0;
}
