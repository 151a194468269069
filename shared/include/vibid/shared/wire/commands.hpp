// Command ids and the payload of every request and response, defined once for the board and the
// host. Each payload has a fixed size kBytes (a few, marked, take a variable tail), an Encode
// that writes exactly kBytes, and a Decode that refuses any other length.
//
// Conversation: the host sends one request report; the device answers with one response report
// carrying the same command and token, kFlagResponse, and a Status. Two commands answer with a
// stream (log-read, cal-get): data reports with sequence 0, 1, 2, ... (modulo 2^16: a stream
// that follows a long acquisition wraps) and then one trailer report flagged kFlagStreamEnd whose
// sequence is the number of data reports (modulo 2^16) and whose payload starts
// with StreamTrailer (byte count and CRC-32 of all data payload bytes). Streams are not
// acknowledged per report; a lost report shows as a sequence gap or a CRC mismatch, and the host
// asks again (log-read resumes from a record index). A refused request gets a single response
// report with the refusal status and, from protocol 2.1, a Refusal payload naming the reason
// (refusal.hpp).
//
// Calibration upload (cal-put): cal-put-begin announces the record length and CRC-32, then one
// cal-put-data report per 52-byte chunk with sequence 0, 1, ...; each is answered. The answer to
// the last chunk carries the verdict on the whole record (CRC, version, ranges, filter
// stability). cal-commit then writes the staged record to flash.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/device.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::wire {

enum class Command : std::uint8_t {
  kPing = 0x01,            ///< Echoes its payload.
  kGetInfo = 0x02,         ///< -> InfoResponse.
  kGetStatus = 0x03,       ///< -> StatusResponse.
  kReset = 0x04,           ///< Answers, then resets the board.
  kEnterDfu = 0x05,        ///< Answers, then enters the DFU bootloader (refused while acquiring).
  kSelfTest = 0x06,        ///< SelfTestRequest -> SelfTestResponse (refused while acquiring). 2.1.
  kCalPutBegin = 0x10,     ///< CalPutBeginRequest.
  kCalPutData = 0x11,      ///< Chunk of the record; header.sequence = chunk index.
  kCalCommit = 0x12,       ///< -> CalCommitResponse (refused while acquiring).
  kCalGet = 0x13,          ///< -> stream of the active record, trailer CalGetTrailer.
  kAcqConfigure = 0x20,    ///< AcqConfigureRequest -> AcqConfigureResponse.
  kAcqStart = 0x21,        ///< Clears the log and arms the trigger.
  kAcqStop = 0x22,         ///< -> AcqStopResponse; keeps the log. Idempotent.
  kReadLatest = 0x23,      ///< -> LatestResponse (live values for a monitor).
  kLogRead = 0x24,         ///< LogReadRequest -> stream of log records, trailer LogTrailer.
  kGetClips = 0x25,        ///< -> ClipResponse (clipped samples per channel). Protocol 2.1.
  kDobControl = 0x30,      ///< DobControlRequest: run or stop the observer.
  kSelectScenario = 0x70,  ///< Emulator only (kCapScenarioSelect): ScenarioRequest.
  kInjectFrames = 0x71,    ///< QEMU image only (kCapSampleInjection): InjectFramesRequest.
};

/// Ids 0x70..0x7F belong to a port; the core hands them to the port's handler.
constexpr bool IsPortCommand(std::uint8_t id) { return id >= 0x70 && id <= 0x7F; }

/// Acquisition state (status, log trailer, latest).
enum class AcqState : std::uint8_t {
  kIdle = 0,       ///< Not sampling (never started, or stopped). The log is kept.
  kArmed = 1,      ///< Sampling; waiting for the trigger, keeping pre-trigger records.
  kAcquiring = 2,  ///< Triggered; appending to the log.
  kDone = 3,       ///< The record limit was reached; sampling stopped. The log is kept.
};

enum class CalState : std::uint8_t {
  kUncalibrated = 0,  ///< Neither flash slot holds a valid record: defaults (raw counts, no DOB).
  kCalibrated = 1,
};

inline constexpr std::uint8_t kNoSlot = 0xFF;
inline constexpr std::uint32_t kNoRecord = 0xFFFFFFFFu;

enum class TriggerMode : std::uint8_t {
  kImmediate = 0,  ///< The first record is the trigger; no pre-trigger records.
  kRising = 1,     ///< Fires when the calibrated force reaches threshold or more.
  kFalling = 2,    ///< Fires when the calibrated force reaches threshold or less.
};

/// Acquisition limits the device enforces (AcqConfigure refusals).
inline constexpr std::uint32_t kMinSamplePeriodUs = 100;      ///< 10 kHz.
inline constexpr std::uint32_t kMaxSamplePeriodUs = 1000000;  ///< 1 Hz.
/// Decimation factors 2^a 5^b up to this one; each runs the anti-aliasing decimator
/// (vibid/shared/fixed/decimator.hpp) on every logged channel and d_hat.
inline constexpr std::uint16_t kMaxDecimation = 1000;

inline constexpr std::uint8_t kAcqFlagLogDob = 1u << 0;  ///< Each log record carries d_hat.
/// acq-start streams the log: after its answer the device sends a log-read stream from record 0
/// with acq-start's token, following the acquisition as records arrive (one data report per
/// frame at most) until it ends and every record went out, then the trailer. Nothing waits for
/// a host request between reports, so what reaches the host depends only on the link.
inline constexpr std::uint8_t kAcqFlagStream = 1u << 1;
/// Each log record carries the observer's residual test after d_hat (needs kAcqFlagLogDob and a
/// calibration with the test): u32, bits 0..30 its statistic g (Q16, at most 2^30), bit 31 the
/// model-stale flag, both as they stood at the record's time (its tick less the decimator's
/// delay, as the host writes it), to within one record: a state, so it skips the filter.
inline constexpr std::uint8_t kAcqFlagLogWatch = 1u << 2;
inline constexpr std::uint8_t kAcqKnownFlags = kAcqFlagLogDob | kAcqFlagStream | kAcqFlagLogWatch;

// ---------------------------------------------------------------------------------------------
// get-info response
//   0  u8  protocol_major          1  u8  protocol_minor
//   2  u8  fw_major                3  u8  fw_minor           4  u16 fw_patch
//   6  u16 board_id (BoardId)      8  u32 build_id           12 u32 capabilities
//   16 u32 sample_period_us (the configured period)          20 u32 min_sample_period_us
//   24 u32 log_capacity_bytes      28 u16 link_reports_per_s 30 u8  adc_bits
//   31 u8  reset_cause             32 u8  channel_kind[6]    38 u8  cal_state
//   39 u8  cal_slot (kNoSlot if none)                        40 u32 cal_crc (0 if uncalibrated)
//   44 u32 overrun_count           48 u32 dropped_records
// Bytes 20..35 are the board profile (board_profile.hpp): the host computes its link budget
// from them (link bytes/s = link_reports_per_s x 64).
struct InfoResponse {
  static constexpr std::size_t kBytes = 52;
  std::uint8_t protocol_major = kProtocolMajor;
  std::uint8_t protocol_minor = kProtocolMinor;
  std::uint8_t fw_major = 0;
  std::uint8_t fw_minor = 0;
  std::uint16_t fw_patch = 0;
  BoardId board_id = BoardId::kHostTest;
  std::uint32_t build_id = 0;
  std::uint32_t capabilities = 0;
  std::uint32_t sample_period_us = 0;
  std::uint32_t min_sample_period_us = kMinSamplePeriodUs;
  std::uint32_t log_capacity_bytes = 0;
  std::uint16_t link_reports_per_s = 0;
  std::uint8_t adc_bits = 0;
  ResetCause reset_cause = ResetCause::kUnknown;
  std::array<ChannelKind, kChannelCount> channel_kind{};
  CalState cal_state = CalState::kUncalibrated;
  std::uint8_t cal_slot = kNoSlot;
  std::uint32_t cal_crc = 0;
  std::uint32_t overrun_count = 0;
  std::uint32_t dropped_records = 0;
};
static_assert(InfoResponse::kBytes <= kMaxPayload);

// get-info request, protocol 2.1: no payload asks for InfoResponse, as in 2.0; one byte asks for
// a further page of facts the 52-byte InfoResponse has no room for:
//   0 u8 page    kInfoPageSampling -> SamplingInfoResponse, kInfoPageHealth ->
//                HealthInfoResponse; any other page is refused
// A 2.0 board refuses any payload (kInvalidArgument): a host asks for a page only of a board whose
// InfoResponse says protocol_minor >= 1.
inline constexpr std::uint8_t kInfoPageSampling = 1;
inline constexpr std::uint8_t kInfoPageHealth = 2;
struct InfoPageRequest {
  static constexpr std::size_t kBytes = 1;
  std::uint8_t page = kInfoPageSampling;
};

// get-info page kInfoPageSampling (protocol 2.1): when the board samples each channel.
//   0 u32 sample_instant_ns[6]   after the sample timer's edge, in ns, wire::Channel order
// Channels sampled at different instants see a common signal with a phase difference of
// 2 pi f (t_a - t_b); the host compensates a cross spectrum with them (docs/board.md).
struct SamplingInfoResponse {
  static constexpr std::size_t kBytes = 24;
  std::array<std::uint32_t, kChannelCount> sample_instant_ns{};
};

// get-info page kInfoPageHealth (protocol 2.1): the supply, clock and reset facts of the board.
//   0 u8 brown_out (BrownOut: the level below which the board holds itself in reset)
//   1 u8 reset_cause (ResetCause, as in InfoResponse)   2 u8 clock (ClockState)
//   3 u8 reserved (0)
//   4 u32 hse_measured_hz   the crystal as the board measured it at start against its internal
//                           oscillator (+-1 % at 25 C), 0 if not measured
//   8 u32 sampler_recoveries  converter/DMA restarts after an overrun or a transfer error
struct HealthInfoResponse {
  static constexpr std::size_t kBytes = 12;
  BrownOut brown_out = BrownOut::kUnknown;
  ResetCause reset_cause = ResetCause::kUnknown;
  ClockState clock = ClockState::kUnknown;
  std::uint32_t hse_measured_hz = 0;
  std::uint32_t sampler_recoveries = 0;
};

// get-info page kInfoPageFault: the record the fault handler kept across the reset it made
// (reset cause kFault). Firmware without the page refuses it (invalid-argument, reason
// unknown-info-page); a host asks for it only of a board whose reset cause is kFault.
//   0 u8 recorded (1: the last reset was a fault and this is its record; 0: all zero)
//   1 u8 exception (the IPSR exception number: 2 NMI, 3 HardFault, 4 MemManage, 5 BusFault,
//        6 UsageFault, 16 + n interrupt n without a handler)
//   2 u16 reserved (0)
//   4 u32 cfsr   8 u32 hfsr   12 u32 mmfar   16 u32 bfar   (Cortex-M4 SCB fault registers)
//   20 u32 pc    24 u32 lr    (stacked by the exception entry; 0xFFFFFFFF: the stack was not
//                             readable, so nothing was taken from it)
inline constexpr std::uint8_t kInfoPageFault = 4;
inline constexpr std::uint32_t kFaultNoStackedValue = 0xFFFFFFFFu;
struct FaultInfoResponse {
  static constexpr std::size_t kBytes = 28;
  std::uint8_t recorded = 0;
  std::uint8_t exception = 0;
  std::uint32_t cfsr = 0;
  std::uint32_t hfsr = 0;
  std::uint32_t mmfar = 0;
  std::uint32_t bfar = 0;
  std::uint32_t pc = 0;
  std::uint32_t lr = 0;
};

// ---------------------------------------------------------------------------------------------
// self-test (protocol 2.1): the board checks one of a fixed set of numbered checks per request;
// the host asks for check 0, 1, ... up to the check_count the first answer states.
enum class SelfTestCheck : std::uint8_t {
  kHsePpm = 0,       ///< Crystal error against the host's 1 ms USB start-of-frame, ppm.
  kVdda = 1,         ///< Analog supply from VREFINT and its factory calibration, V.
  kNoiseForce1 = 2,  ///< Idle noise, LSB rms, of each converter channel (wire::Channel order),
  kNoiseForce2 = 3,  ///< over kSelfTestSamples samples at the configured period.
  kNoiseAccel1 = 4,
  kNoiseAccel2 = 5,
  kOffsetForce1 = 6,  ///< Idle mean minus the converter's mid code, LSB, same samples.
  kOffsetForce2 = 7,
  kOffsetAccel1 = 8,
  kOffsetAccel2 = 9,
  kEncoder1 = 10,  ///< The encoder timer runs; value: its count.
  kEncoder2 = 11,
  kImageCrc = 12,  ///< CRC-32 of the firmware image against the one the build stored.
  kCalSlotA = 13,  ///< SelfTestSlot of calibration slot A.
  kCalSlotB = 14,
  kBrownOut = 15,    ///< BrownOut level; passes at kLevel3.
  kResetCause = 16,  ///< ResetCause; passes unless kFault (get-info page kInfoPageFault).
  kHsePpmLse = 17,   ///< Crystal error against the board's 32.768 kHz LSE crystal, ppm.
};
inline constexpr std::uint8_t kSelfTestCheckCount = 18;
/// Samples each noise and offset check takes.
inline constexpr std::uint32_t kSelfTestSamples = 1000;
/// The longest a board spends on one check before it answers: the crystal check counts 1000 USB
/// frames (1 s); a noise or offset check takes kSelfTestSamples frames at a period of at most
/// 1 ms (a board configured slower answers unavailable) plus 100 ms of slack. A host waits this
/// long on top of its usual answer timeout, so it never sends the request again (and makes the
/// board measure twice) while the first measurement runs.
inline constexpr std::uint32_t kSelfTestLongestCheckMs = 1100;

enum class SelfTestVerdict : std::uint8_t {
  kFail = 0,
  kPass = 1,
  kUnavailable = 2,  ///< This port cannot measure it (neither pass nor fail).
};

enum class SelfTestUnit : std::uint8_t {
  kNone = 0,
  kPpm = 1,
  kVolt = 2,
  kLsbRms = 3,
  kLsb = 4,
  kCount = 5,
  kCrc32 = 6,       ///< The mantissa is the CRC (u32).
  kSlot = 7,        ///< SelfTestSlot.
  kBrownOut = 8,    ///< BrownOut.
  kResetCause = 9,  ///< ResetCause.
};

/// What a measured value was taken against (self-test response byte 5): the crystal checks name
/// their time reference, the offset checks the idle code they subtract.
enum class SelfTestReference : std::uint8_t {
  kNone = 0,         ///< The check has no reference (or the board does not say).
  kUsbFrames = 1,    ///< The host's 1 ms USB start-of-frame (USB 2.0: +-500 ppm).
  kLse = 2,          ///< The board's 32.768 kHz LSE crystal.
  kMidCode = 3,      ///< The converter's mid code (2048): no calibrated zero for the channel.
  kCalibration = 4,  ///< The channel's calibrated zero (offset_counts of the active record).
};

/// A calibration slot's state (check kCalSlotA/B): a damaged slot fails.
enum class SelfTestSlot : std::uint8_t { kErased = 0, kValid = 1, kDamaged = 2 };

// self-test request: 0 u8 check (0 .. kSelfTestCheckCount - 1; a larger one is refused,
// invalid-argument, reason unknown-check)
struct SelfTestRequest {
  static constexpr std::size_t kBytes = 1;
  std::uint8_t check = 0;
};

// self-test response
//   0 u8 check   1 u8 check_count   2 u8 verdict (SelfTestVerdict)   3 u8 unit (SelfTestUnit)
//   4 i8 exp10   5 u8 reference (SelfTestReference)   6 u16 reserved   8 i64 mantissa
//   value = mantissa x 10^exp10
struct SelfTestResponse {
  static constexpr std::size_t kBytes = 16;
  std::uint8_t check = 0;
  std::uint8_t check_count = kSelfTestCheckCount;
  SelfTestVerdict verdict = SelfTestVerdict::kUnavailable;
  SelfTestUnit unit = SelfTestUnit::kNone;
  std::int8_t exp10 = 0;
  SelfTestReference reference = SelfTestReference::kNone;
  std::int64_t mantissa = 0;
};

/// Short stable name of a check ("hse-ppm"), "unknown" otherwise.
const char* SelfTestCheckName(std::uint8_t check);

// ---------------------------------------------------------------------------------------------
// get-status response
//   0  u8  acq_state    1  u8  dob_running (0/1)   2  u8  cal_state   3  u8  cal_staged (0/1)
//   4  u64 uptime_us
//   12 u32 ticks (frames seen since acq-start)     16 u32 records_written (log records, total)
//   20 u32 oldest_record (the oldest record a log-read can still return; = records_written
//          when the log is empty. Pulled records stay readable until the log overwrites them.)
//   24 u32 overrun_count   28 u32 dropped_records  32 u32 rejected_requests
//   36 u32 saturation_count (clipped samples of all channels, get-clips, + DOB saturations)
//   40 u32 trigger_record (kNoRecord until triggered)
//   44 u32 cal_sequence    48 u32 flash_errors
struct StatusResponse {
  static constexpr std::size_t kBytes = 52;
  AcqState acq_state = AcqState::kIdle;
  std::uint8_t dob_running = 0;
  CalState cal_state = CalState::kUncalibrated;
  std::uint8_t cal_staged = 0;
  std::uint64_t uptime_us = 0;
  std::uint32_t ticks = 0;
  std::uint32_t records_written = 0;
  std::uint32_t oldest_record = 0;
  std::uint32_t overrun_count = 0;
  std::uint32_t dropped_records = 0;
  std::uint32_t rejected_requests = 0;
  std::uint32_t saturation_count = 0;
  std::uint32_t trigger_record = kNoRecord;
  std::uint32_t cal_sequence = 0;
  std::uint32_t flash_errors = 0;
};
static_assert(StatusResponse::kBytes <= kMaxPayload);

// ---------------------------------------------------------------------------------------------
// acq-configure request
//   0  u32 sample_period_us        kMinSamplePeriodUs..kMaxSamplePeriodUs
//   4  u8  channel_mask            bit i = Channel(i); nonzero, within kAllChannelsMask
//   5  u8  flags                   kAcqFlagLogDob, kAcqFlagStream, kAcqFlagLogWatch
//   6  u16 decimation              2^a 5^b up to kMaxDecimation: one log record every
//                                  `decimation` ticks, through the anti-aliasing decimator
//   8  u8  trigger_mode            TriggerMode
//   9  u8  trigger_channel         a load-cell channel (ignored for kImmediate, must be 0)
//   10 u16 reserved                0
//   12 i32 trigger_threshold       calibrated units of the trigger channel (Q31 of full scale)
//   16 u32 pretrigger_records      0 for kImmediate; < log capacity in records
//   20 u32 record_limit            records after the trigger, then stop; 0 = until acq-stop
struct AcqConfigureRequest {
  static constexpr std::size_t kBytes = 24;
  std::uint32_t sample_period_us = 0;
  std::uint8_t channel_mask = 0;
  std::uint8_t flags = 0;
  std::uint16_t decimation = 1;
  TriggerMode trigger_mode = TriggerMode::kImmediate;
  std::uint8_t trigger_channel = 0;
  std::int32_t trigger_threshold = 0;
  std::uint32_t pretrigger_records = 0;
  std::uint32_t record_limit = 0;
};

// acq-configure response: 0 u16 record_bytes  2 u16 reserved  4 u32 capacity_records
struct AcqConfigureResponse {
  static constexpr std::size_t kBytes = 8;
  std::uint16_t record_bytes = 0;
  std::uint32_t capacity_records = 0;
};

// acq-stop response: 0 u32 records_written
struct AcqStopResponse {
  static constexpr std::size_t kBytes = 4;
  std::uint32_t records_written = 0;
};

// ---------------------------------------------------------------------------------------------
// read-latest response (the newest frame after calibration; for a live monitor)
//   0  u32 tick    4  i32 calibrated[6] (Q31 of each channel's full scale)   28 i32 d_hat (Q31)
//   32 u8  acq_state   33 u8 dob_running
struct LatestResponse {
  static constexpr std::size_t kBytes = 34;
  std::uint32_t tick = 0;
  std::array<std::int32_t, kChannelCount> calibrated{};
  std::int32_t d_hat = 0;
  AcqState acq_state = AcqState::kIdle;
  std::uint8_t dob_running = 0;
};

// ---------------------------------------------------------------------------------------------
// get-clips response (protocol 2.1): clipped samples per channel since acq-start
//   0  u32 ticks (frames sampled since acq-start, as get-status)   4 u32 clipped[6]
// A sample is clipped on its channel when its converter code sits at either end of the ADC's
// range (0 or 2^adc_bits - 1), or when its calibration saturates (the value is beyond the
// channel's calibrated full scale). Each sample counts once per channel. get-status
// saturation_count is the sum over the channels plus the observer's saturations.
struct ClipResponse {
  static constexpr std::size_t kBytes = 28;
  std::uint32_t ticks = 0;
  std::array<std::uint32_t, kChannelCount> clipped{};
};

// ---------------------------------------------------------------------------------------------
// log-read request: 0 u32 first_record  4 u32 max_records (0 = all available; kLogReadFollow:
// follow the acquisition, as the stream acq-start starts does)
// Records below first_record are released: the device may reuse their space, but they stay
// readable until it does (get-status oldest_record), so a log pulled while sampling can be pulled
// again. A pull that broke off resumes by asking again from the first record it did not receive
// intact. A record overwritten before or while it is streamed refuses the request (out-of-range).
// A following stream sends records as they are written, releases what it sent and ends once
// sampling ended and every record went out: the resume of a broken acquisition stream, which
// keeps the link as busy as the original stream did. Not sampling, it is an "all available" pull.
inline constexpr std::uint32_t kLogReadFollow = 0xFFFFFFFFu;
struct LogReadRequest {
  static constexpr std::size_t kBytes = 8;
  std::uint32_t first_record = 0;
  std::uint32_t max_records = 0;
};

// Every stream trailer starts with these 8 bytes: 0 u32 total_bytes  4 u32 crc32 (of all data
// payload bytes of the stream, in sequence order).
struct StreamTrailer {
  static constexpr std::size_t kBytes = 8;
  std::uint32_t total_bytes = 0;
  std::uint32_t crc32 = 0;
};

// log-read trailer
//   0  u32 total_bytes   4  u32 crc32        8  u32 first_record   12 u32 record_count
//   16 u16 record_bytes  18 u8  channel_mask 19 u8  acq_flags      20 u32 sample_period_us
//   24 u16 decimation    26 u8  acq_state    27 u8  reserved       28 u32 trigger_record
//   32 u32 dropped_records   36 u32 overrun_count   40 u32 records_written
struct LogTrailer {
  static constexpr std::size_t kBytes = 44;
  StreamTrailer stream;
  std::uint32_t first_record = 0;
  std::uint32_t record_count = 0;
  std::uint16_t record_bytes = 0;
  std::uint8_t channel_mask = 0;
  std::uint8_t acq_flags = 0;
  std::uint32_t sample_period_us = 0;
  std::uint16_t decimation = 0;
  AcqState acq_state = AcqState::kIdle;
  std::uint32_t trigger_record = kNoRecord;
  std::uint32_t dropped_records = 0;
  std::uint32_t overrun_count = 0;
  std::uint32_t records_written = 0;
};

// cal-get trailer: 0 u32 total_bytes  4 u32 crc32  8 u8 slot  9 u8[3] reserved  12 u32 sequence
struct CalGetTrailer {
  static constexpr std::size_t kBytes = 16;
  StreamTrailer stream;
  std::uint8_t slot = kNoSlot;
  std::uint32_t sequence = 0;
};

// cal-put-begin request: 0 u32 record_bytes  4 u32 crc32 (of the whole record as sent)
struct CalPutBeginRequest {
  static constexpr std::size_t kBytes = 8;
  std::uint32_t record_bytes = 0;
  std::uint32_t crc32 = 0;
};

// cal-commit response: 0 u8 slot  1 u8[3] reserved  4 u32 sequence
struct CalCommitResponse {
  static constexpr std::size_t kBytes = 8;
  std::uint8_t slot = kNoSlot;
  std::uint32_t sequence = 0;
};

// dob-control request: 0 u8 run (0 stop, 1 run; a run restarts the filter from zero state)
struct DobControlRequest {
  static constexpr std::size_t kBytes = 1;
  std::uint8_t run = 0;
};

// select-scenario request (emulator): 0 char name[16] (ASCII, NUL-padded)  16 f32 params[4]
// (IEEE-754 binary32; meaning per scenario, SI units)
struct ScenarioRequest {
  static constexpr std::size_t kBytes = 32;
  static constexpr std::size_t kNameBytes = 16;
  std::array<char, kNameBytes> name{};
  std::array<float, 4> params{};
};

// inject-frames request (QEMU image): 0 u8 frame_count (1..2)  1 u8[3] reserved
//   4 + 24 k: i32 raw[6] of frame k
struct InjectFramesRequest {
  static constexpr std::size_t kMaxFrames = 2;
  static constexpr std::size_t kBytes = 4 + kMaxFrames * 4 * kChannelCount;
  std::uint8_t frame_count = 0;
  std::array<std::array<std::int32_t, kChannelCount>, kMaxFrames> raw{};
};
static_assert(InjectFramesRequest::kBytes == 52);

// Codecs. Encode writes exactly kBytes into `out` (which must hold at least that many).
// Decode: kOk; kInvalidArgument if in.size() != kBytes (or an enum byte is out of range,
// or a reserved byte is nonzero).
void Encode(const InfoResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, InfoResponse& v);
void Encode(const StatusResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, StatusResponse& v);
void Encode(const InfoPageRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, InfoPageRequest& v);
void Encode(const SamplingInfoResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, SamplingInfoResponse& v);
void Encode(const HealthInfoResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, HealthInfoResponse& v);
void Encode(const FaultInfoResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, FaultInfoResponse& v);
void Encode(const SelfTestRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, SelfTestRequest& v);
void Encode(const SelfTestResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, SelfTestResponse& v);
void Encode(const AcqConfigureRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, AcqConfigureRequest& v);
void Encode(const AcqConfigureResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, AcqConfigureResponse& v);
void Encode(const AcqStopResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, AcqStopResponse& v);
void Encode(const LatestResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, LatestResponse& v);
void Encode(const ClipResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, ClipResponse& v);
void Encode(const LogReadRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, LogReadRequest& v);
void Encode(const StreamTrailer& v, std::span<std::uint8_t> out);
/// Reads the first kBytes of any stream trailer (a longer payload is allowed).
Status Decode(std::span<const std::uint8_t> in, StreamTrailer& v);
void Encode(const LogTrailer& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, LogTrailer& v);
void Encode(const CalGetTrailer& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, CalGetTrailer& v);
void Encode(const CalPutBeginRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, CalPutBeginRequest& v);
void Encode(const CalCommitResponse& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, CalCommitResponse& v);
void Encode(const DobControlRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, DobControlRequest& v);
void Encode(const ScenarioRequest& v, std::span<std::uint8_t> out);
Status Decode(std::span<const std::uint8_t> in, ScenarioRequest& v);
/// Variable length: 4 + 24 * frame_count bytes.
void Encode(const InjectFramesRequest& v, std::span<std::uint8_t> out);
std::size_t EncodedSize(const InjectFramesRequest& v);
Status Decode(std::span<const std::uint8_t> in, InjectFramesRequest& v);

/// Builds a complete report (a request when flags has no kFlagResponse) around a payload.
/// @returns kOk; kOutOfRange if payload is longer than kMaxPayload.
Status BuildReport(Command command, std::uint16_t token, std::uint16_t sequence, std::uint8_t flags,
                   Status status, std::span<const std::uint8_t> payload, Report& out);

/// A fixed-size payload struct's bytes, for everything that takes a payload as bytes.
template <typename Payload>
requires requires { Payload::kBytes; }
std::array<std::uint8_t, Payload::kBytes> EncodedBytes(const Payload& payload) {
  std::array<std::uint8_t, Payload::kBytes> bytes{};
  Encode(payload, bytes);
  return bytes;
}

/// Encodes a fixed-size payload struct straight into a report.
template <typename Payload>
requires requires { Payload::kBytes; }
Status BuildReport(Command command, std::uint16_t token, std::uint16_t sequence, std::uint8_t flags,
                   Status status, const Payload& payload, Report& out) {
  return BuildReport(command, token, sequence, flags, status, EncodedBytes(payload), out);
}

/// Short stable name of a command id ("log-read"), "unknown" otherwise.
const char* CommandName(std::uint8_t id);

}  // namespace vibid::wire
