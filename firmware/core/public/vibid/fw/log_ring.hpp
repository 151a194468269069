// The acquisition log: fixed-size records in caller-provided storage, written by the sampling
// context and read by the main loop (single producer, single consumer, no lock, no heap). The
// producer is the sampling interrupt on a board, which must never wait for the main loop, so the
// two sides only exchange two counters (written, released) with acquire/release ordering; the
// storage is a static buffer the port hands in.
//
// Records are addressed by log index: 0 is the oldest pre-trigger record kept, the trigger
// record is index pretrigger_kept. Before the trigger the ring keeps only the newest
// `pretrigger` records, overwriting older ones (that is what a pre-trigger buffer is). After the
// trigger a record that finds no free slot is refused and the caller counts it as dropped.
//
// Release and overwrite are two different moments. Release(first_kept), which a log-read
// request does implicitly, only tells the producer it may reuse the slots below first_kept; the
// records stay in them, readable, until the producer actually writes there. So a host that
// pulled while sampling (releasing as it went) can still pull the whole log again afterwards
// when it fitted in the ring, and an interrupted pull can ask again for what it missed.
// Index i lives in the slot index i + capacity will take, so it is intact while
//   i >= released()                   (the producer may not reuse its slot yet), or
//   written() < i + capacity          (index i + capacity has not been started).
// written() == i + capacity means the producer may be writing that slot right now: a reader of
// a released record copies it, then calls Intact(i) again (seqlock style: the producer's
// release fence before it writes a slot pairs with the acquire fence in Intact) and throws the
// copy away if the record was overwritten meanwhile. Release only ever moves forward, so a
// re-read of old records never takes space back from the producer.
//
// Indices are 32-bit: at 10 kHz without decimation they last 4.9 days of one acquisition.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::fw {

class LogRing {
 public:
  /// `storage` must outlive the ring. Its size is the log capacity in bytes.
  explicit LogRing(std::span<std::uint8_t> storage) : storage_(storage) {}

  /// Records of this size would fit: storage bytes / record_bytes.
  std::uint32_t CapacityFor(std::size_t record_bytes) const;

  /// Empties the ring for a new acquisition. Main loop, sampling stopped.
  /// @returns kOk; kInvalidArgument for record_bytes 0; kOutOfRange if pretrigger_records is not
  ///          below the capacity for that record size.
  Status Reset(std::size_t record_bytes, std::uint32_t pretrigger_records);

  // Producer side (sampling context).

  /// Stores one record (record_bytes bytes).
  /// @returns true if kept; false if the ring is full after the trigger (the record is dropped).
  bool Push(std::span<const std::uint8_t> record);

  /// The trigger fired: the pre-trigger records kept so far become log indices 0.. and every
  /// later Push appends. Idempotent.
  void MarkTrigger();

  // Consumer side (main loop).

  bool triggered() const { return triggered_.load(std::memory_order_acquire); }
  /// Log index of the trigger record (the number of pre-trigger records kept); valid once
  /// triggered().
  std::uint32_t trigger_index() const { return trigger_index_; }
  /// Records in the log (indices [0, written())); 0 before the trigger.
  std::uint32_t written() const;
  /// Records below this index were released: the producer may reuse their slots.
  std::uint32_t released() const { return released_.load(std::memory_order_relaxed); }
  /// The oldest index Read can still return (written() when the log is empty).
  std::uint32_t oldest() const;
  std::size_t record_bytes() const { return record_bytes_; }
  std::uint32_t capacity_records() const { return capacity_; }
  std::size_t storage_bytes() const { return storage_.size(); }

  /// Lets the producer reuse the slots of every record below first_kept. Never moves back: a
  /// first_kept below released() changes nothing.
  /// @returns kOk; kOutOfRange if first_kept > written().
  Status Release(std::uint32_t first_kept);

  /// True if the record at `index` is written and not overwritten (see the header comment).
  /// After copying a released record, call it again: false means the copy may be torn.
  bool Intact(std::uint32_t index) const;

  /// The record at `index`: a view into the storage, valid while Intact(index).
  /// @returns kOk; kOutOfRange if the index is not written yet or was overwritten.
  Status Read(std::uint32_t index, std::span<const std::uint8_t>& record) const;

 private:
  std::span<std::uint8_t> storage_;
  std::size_t record_bytes_ = 0;
  std::uint32_t capacity_ = 0;
  std::uint32_t pretrigger_ = 0;

  // Producer-owned.
  std::uint32_t write_slot_ = 0;
  std::uint32_t pre_kept_ = 0;
  std::uint32_t start_slot_ = 0;     // slot of log index 0; published by triggered_
  std::uint32_t trigger_index_ = 0;  // published by triggered_
  std::atomic<bool> triggered_{false};
  std::atomic<std::uint32_t> written_{0};

  // Consumer-owned.
  std::atomic<std::uint32_t> released_{0};
};

}  // namespace vibid::fw
