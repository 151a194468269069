// The recording reader: CSV text to numeric columns, fast enough for records of millions of rows.
//
// How: the file is memory-mapped (no copy into a string), the body after the header is cut at line
// boundaries into one chunk per thread, and each thread parses its rows straight from the buffer
// into the final column vectors (no per-cell strings, no per-row allocation): plain decimals by an
// exact fast path, everything else by std::from_chars. Row
// offsets come from a first pass that counts newlines, so every chunk knows where its rows go.
//
// Errors: the fast path only recognises well-formed rows. At the first row it cannot take, a chunk
// stops and remembers where; the earliest such row in file order is then re-read by the plain
// checker (SplitCells + ParseNumber), which builds the message naming the line and the column. So
// the messages are the same whatever the thread count, and the result never depends on it.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <thread>

#include "csv_detail.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid {
namespace {

// Below this many body bytes a second thread costs more than it saves.
constexpr std::size_t kMinBytesPerThread = std::size_t{1} << 20;

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

const char* SkipBlanks(const char* p, const char* end) {
  while (p != end && IsBlank(*p)) ++p;
  return p;
}

const char* NextLine(const char* p, const char* end) {
  const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
  return nl ? static_cast<const char*>(nl) + 1 : end;
}

// The line starting at `line` and ending before `next` (the start of the following line), without
// its newline and surrounding blanks.
std::string_view LineText(const char* line, const char* next) {
  if (next != line && next[-1] == '\n') --next;
  return csv_detail::Trim(std::string_view(line, static_cast<std::size_t>(next - line)));
}

// Upper bound of the data rows in [p, end): its line count. This pass reads the whole file, so it
// runs at memory speed: sixteen bytes per step where SSE2 is there (each newline byte subtracts -1
// from its byte counter, the counters summed before they can wrap), then eight bytes at a time: a
// byte of w ^ 0x0a..0a is zero exactly where w holds a newline, and the classic carry-free test
// below sets the top bit of exactly those bytes (no false positives, unlike the (x - 0x01..)
// variant).
std::size_t CountLines(const char* const begin, const char* const end) {
  std::size_t newlines = 0;
  const char* p = begin;
#if defined(__SSE2__)
  const __m128i newline = _mm_set1_epi8('\n');
  while (end - p >= 16) {
    const auto blocks = std::min<std::ptrdiff_t>(255, (end - p) / 16);
    __m128i counts = _mm_setzero_si128();
    for (std::ptrdiff_t i = 0; i < blocks; ++i, p += 16) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
      counts = _mm_sub_epi8(counts, _mm_cmpeq_epi8(v, newline));
    }
    const __m128i sums = _mm_sad_epu8(counts, _mm_setzero_si128());
    newlines += static_cast<std::size_t>(_mm_cvtsi128_si64(sums) +
                                         _mm_cvtsi128_si64(_mm_unpackhi_epi64(sums, sums)));
  }
#endif
  constexpr std::uint64_t kNewlines = 0x0a0a0a0a0a0a0a0aull;
  constexpr std::uint64_t kLow7 = 0x7f7f7f7f7f7f7f7full;
  const char* const p_end = p + (end - p) / 8 * 8;
  for (; p != p_end; p += 8) {
    std::uint64_t w = 0;
    std::memcpy(&w, p, 8);
    const std::uint64_t t = w ^ kNewlines;
    const std::uint64_t zero_bytes = ~(((t & kLow7) + kLow7) | t | kLow7);
    // One bit per byte at bit 7: summed into the top byte by one multiplication.
    newlines += static_cast<std::size_t>(((zero_bytes >> 7) * 0x0101010101010101ull) >> 56);
  }
  for (; p != end; ++p) newlines += *p == '\n' ? 1u : 0u;
  // A last line without a newline is a line too.
  const bool open_last = end != begin && end[-1] != '\n';
  return newlines + (open_last ? 1u : 0u);
}

// Exact powers of ten: 10^k is a double without rounding for k <= 22 (5^22 < 2^53).
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// The common case of a decimal number, without a library call: [-]digits[.digits][(e|E)[+-]digits]
// with at most 19 digits whose value m is at most 2^53 and a decimal exponent e with |e| <= 22.
// Then m and 10^|e| are exact doubles and one IEEE multiplication or division rounds m 10^e
// correctly (Clinger's fast path), the same double std::from_chars returns. Anything else (more
// digits, a larger exponent, inf/nan, hex, a leading '.') returns false and goes to
// std::from_chars. The value of eight ASCII digits loaded little-endian (the first digit the most
// significant): pairs, then quads, then the eight by three multiplications instead of eight
// dependent steps.
inline std::uint64_t EightDigitsValue(std::uint64_t w) {
  static_assert(std::endian::native == std::endian::little);
  w -= 0x3030303030303030ull;
  w = w * 10 + (w >> 8);
  return (((w & 0x000000FF000000FFull) * (100 + (1000000ull << 32))) +
          (((w >> 16) & 0x000000FF000000FFull) * (1 + (10000ull << 32)))) >>
         32;
}

constexpr std::uint64_t kPow10Int[] = {1,      10,      100,      1000,     10000,
                                       100000, 1000000, 10000000, 100000000};

// Appends the decimal digits at q to m and counts them: the same m (mod 2^64) as one digit at a
// time, up to eight per step. A byte is a digit when its high nibble is 3 and adding 6 carries out
// of its low nibble into nothing; a carry from a lower byte only comes from a byte that is not a
// digit, so the first byte that fails the test is the first non-digit. Its position k tells how
// many digits lead the word; shifted up by 8 - k bytes over '0's, they are an eight-digit number.
const char* ReadDigits(const char* q, const char* end, std::uint64_t& m, int& count) {
  while (end - q >= 8) {
    std::uint64_t w = 0;
    std::memcpy(&w, q, 8);
    const std::uint64_t other = ((w & 0xF0F0F0F0F0F0F0F0ull) |
                                 (((w + 0x0606060606060606ull) & 0xF0F0F0F0F0F0F0F0ull) >> 4)) ^
                                0x3333333333333333ull;
    if (other == 0) {
      m = m * 100000000u + EightDigitsValue(w);
      q += 8;
      count += 8;
      continue;
    }
    const auto k = static_cast<unsigned>(std::countr_zero(other)) / 8;
    if (k != 0) {
      const std::uint64_t aligned = (w << (64 - 8 * k)) | (0x3030303030303030ull >> (8 * k));
      m = m * kPow10Int[k] + EightDigitsValue(aligned);
      q += k;
      count += static_cast<int>(k);
    }
    return q;
  }
  for (; q != end && static_cast<unsigned>(*q - '0') <= 9u; ++q, ++count)
    m = m * 10u + static_cast<unsigned>(*q - '0');
  return q;
}

bool ParseSimpleNumber(const char*& p, const char* end, double& value) {
  const char* q = p;
  const bool negative = q != end && *q == '-';
  if (negative) ++q;
  std::uint64_t m = 0;
  int digits = 0;
  int exp10 = 0;
  const char* const int_start = q;
  // Past 19 digits m may wrap; it is not used then (digits > 19 returns false below).
  q = ReadDigits(q, end, m, digits);
  if (q == int_start) return false;
  if (q != end && *q == '.') {
    int fraction = 0;
    q = ReadDigits(q + 1, end, m, fraction);
    digits += fraction;
    exp10 -= fraction;
  }
  if (digits > 19) return false;
  if (q != end && (*q == 'e' || *q == 'E')) {
    ++q;
    bool exp_negative = false;
    if (q != end && (*q == '+' || *q == '-')) exp_negative = *q++ == '-';
    const char* const exp_start = q;
    int e = 0;
    for (; q != end && static_cast<unsigned>(*q - '0') <= 9u && e < 1000; ++q)
      e = e * 10 + (*q - '0');
    if (q == exp_start || (q != end && static_cast<unsigned>(*q - '0') <= 9u)) return false;
    exp10 += exp_negative ? -e : e;
  }
  if (m > (std::uint64_t{1} << 53) || exp10 < -22 || exp10 > 22) return false;
  const double mag = static_cast<double>(m);
  const double v = exp10 < 0 ? mag / kPow10[-exp10] : mag * kPow10[exp10];
  value = negative ? -v : v;
  p = q;
  return true;
}

struct Chunk {
  const char* begin = nullptr;
  const char* end = nullptr;
  std::size_t first_row = 0;       ///< Row index the chunk's first data row goes to.
  std::size_t rows = 0;            ///< Rows parsed.
  const char* bad_line = nullptr;  ///< Start of the first line the fast path refused, or null.
};

// Parses the rows of one chunk into columns[c][first_row + i] (a null columns[c]: cell skipped).
// Stops at the first line that is not
// a well-formed row of finite numbers (the caller re-reads it to say why).
void ParseChunk(Chunk& chunk, const std::vector<double*>& columns) {
  const std::size_t ncols = columns.size();
  const char* p = chunk.begin;
  const char* const end = chunk.end;
  std::size_t row = chunk.first_row;
  // chunk.rows holds the chunk's line count here: never more rows than that (a guard on the
  // buffer).
  const std::size_t row_limit = chunk.first_row + chunk.rows;
  while (p != end) {
    const char* const line = p;
    p = SkipBlanks(p, end);
    if (p == end) break;
    if (*p == '\n' || *p == '#') {  // empty or comment line
      p = NextLine(p, end);
      continue;
    }
    if (row == row_limit) {
      chunk.bad_line = line;
      break;
    }
    for (std::size_t c = 0; c < ncols; ++c) {
      if (c) p = SkipBlanks(p, end);
      if (columns[c] == nullptr) {
        // A column nobody asked for: its cell is skipped unread, whatever it holds.
        while (p != end && *p != ',' && *p != '\n') ++p;
      } else {
        if (p != end && *p == '+') ++p;
        double v = 0.0;
        if (!ParseSimpleNumber(p, end, v)) {
          const auto [next, ec] = std::from_chars(p, end, v);
          if (ec != std::errc() || !std::isfinite(v)) {
            chunk.bad_line = line;
            chunk.rows = row - chunk.first_row;
            return;
          }
          p = next;
        }
        columns[c][row] = v;
      }
      p = SkipBlanks(p, end);
      const bool last = c + 1 == ncols;
      const bool separator_ok = last ? (p == end || *p == '\n') : (p != end && *p == ',');
      if (!separator_ok) {
        chunk.bad_line = line;
        chunk.rows = row - chunk.first_row;
        return;
      }
      if (p != end) ++p;  // past ',' or '\n'
    }
    ++row;
  }
  chunk.rows = row - chunk.first_row;
}

void RunChunks(std::vector<Chunk>& chunks, const auto& job) {
  std::vector<std::jthread> workers;
  for (std::size_t i = 1; i < chunks.size(); ++i) workers.emplace_back([&, i] { job(chunks[i]); });
  job(chunks[0]);
}

}  // namespace

namespace csv_detail {

// Asks for transparent huge pages on a large buffer about to be written (Linux, THP in "madvise"
// mode): a record's columns are hundreds of megabytes, and faulting them in 4 KiB pages costs as
// much as parsing them. Only the page-aligned interior is advised; a refusal changes nothing.
void AdviseHugePages(void* data, std::size_t bytes) {
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  if (bytes < 2 * kHuge) return;
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const auto first = (reinterpret_cast<std::uintptr_t>(data) + page - 1) / page * page;
  const auto last = (reinterpret_cast<std::uintptr_t>(data) + bytes) / page * page;
  if (last > first)
    static_cast<void>(::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE));
}

}  // namespace csv_detail

namespace {

// Which header columns are read: all without `wanted`; else the required ones (each must be
// there) and the optional ones that are.
std::vector<bool> KeptColumns(const std::vector<std::string>& names, const CsvColumns* wanted,
                              const std::string& where) {
  if (wanted == nullptr) return std::vector<bool>(names.size(), true);
  std::vector<bool> keep(names.size(), false);
  const auto mark = [&](const std::string& name) {
    const auto at = std::find(names.begin(), names.end(), name);
    if (at == names.end()) return false;
    keep[static_cast<std::size_t>(at - names.begin())] = true;
    return true;
  };
  for (const std::string& name : wanted->required) {
    if (!mark(name)) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw InputError(where + "no column '" + Printable(name) + "' (columns: " + list + ")");
    }
  }
  for (const std::string& name : wanted->optional) mark(name);
  return keep;
}

CsvTable ParseCsvImpl(std::string_view text, const std::string& source, std::size_t threads,
                      const CsvColumns* wanted) {
  CsvTable table;
  table.source = source;
  // Spreadsheets save "CSV UTF-8" with a byte-order mark; it is not part of the first name.
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  const char* const begin = text.data();
  const char* const end = begin + text.size();
  const auto line_of = [&](const char* at) {
    return 1 + static_cast<std::size_t>(std::count(begin, at, '\n'));
  };

  // Header: the first line that is neither empty nor a comment.
  const char* body = begin;
  while (body != end || body == begin) {
    const char* const line = body;
    body = NextLine(body, end);
    const std::string_view s = LineText(line, body);
    if (s.empty() || s.front() == '#') {
      if (body == end) break;
      continue;
    }
    // Names are quoted in messages and written to other files: the lines up to here must be text.
    RequireUtf8(std::string_view(begin, static_cast<std::size_t>(body - begin)), source);
    csv_detail::CheckHeader(s, source + ":" + std::to_string(line_of(line)) + ": ", table.names);
    break;
  }
  if (table.names.empty()) throw InputError(source + ": empty file (no header row)");
  const std::vector<std::string> header = std::move(table.names);
  const std::vector<bool> keep = KeptColumns(header, wanted, source + ": ");
  table.names.clear();
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (keep[c]) table.names.push_back(header[c]);
  }
  const std::size_t ncols = table.names.size();

  // Chunks of the body, cut after a newline, one per thread.
  const auto body_bytes = static_cast<std::size_t>(end - body);
  std::size_t nthreads = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  nthreads = std::max<std::size_t>(1, std::min(nthreads, body_bytes / kMinBytesPerThread));
  std::vector<Chunk> chunks(nthreads);
  const char* cut = body;
  for (std::size_t i = 0; i < nthreads; ++i) {
    chunks[i].begin = cut;
    cut = i + 1 == nthreads ? end
                            : NextLine(std::max(cut, body + body_bytes / nthreads * (i + 1)), end);
    chunks[i].end = cut;
  }
  RunChunks(chunks, [](Chunk& c) { c.rows = CountLines(c.begin, c.end); });
  std::size_t capacity = 0;
  for (auto& c : chunks) {
    c.first_row = capacity;
    capacity += c.rows;
  }
  table.columns.resize(ncols);
  for (auto& col : table.columns) {
    col.resize(static_cast<Eigen::Index>(capacity));
    csv_detail::AdviseHugePages(col.data(), capacity * sizeof(double));
  }
  // One pointer per header column, null where the column is skipped.
  std::vector<double*> columns;
  std::vector<double*> kept;
  for (std::size_t c = 0, k = 0; c < header.size(); ++c) {
    columns.push_back(keep[c] ? table.columns[k++].data() : nullptr);
    if (keep[c]) kept.push_back(columns.back());
  }
  RunChunks(chunks, [&columns](Chunk& c) { ParseChunk(c, columns); });

  for (const Chunk& c : chunks) {
    if (!c.bad_line) continue;
    const std::string where = source + ":" + std::to_string(line_of(c.bad_line)) + ": ";
    csv_detail::ExplainBadRow(LineText(c.bad_line, NextLine(c.bad_line, end)), where, header, keep);
  }
  // Blank and comment lines left gaps at the end of a chunk's share: close them up.
  std::size_t rows = 0;
  for (const Chunk& c : chunks) {
    if (c.first_row != rows) {
      for (double* col : kept) std::memmove(col + rows, col + c.first_row, c.rows * sizeof(double));
    }
    rows += c.rows;
  }
  if (rows != capacity) {
    for (auto& col : table.columns) col.conservativeResize(static_cast<Eigen::Index>(rows));
  }
  return table;
}

}  // namespace

CsvTable ParseCsv(std::string_view text, const std::string& source, std::size_t threads) {
  return ParseCsvImpl(text, source, threads, nullptr);
}

CsvTable ParseCsvColumns(std::string_view text, const std::string& source, const CsvColumns& wanted,
                         std::size_t threads) {
  return ParseCsvImpl(text, source, threads, &wanted);
}

namespace {

CsvTable ReadCsvImpl(const std::string& path, const CsvColumns* wanted) {
  RequireReadableSize(path, kMaxCsvFileBytes);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size == 0) {
    // Not a plain file (a pipe, /dev/stdin) or empty: read it the ordinary way.
    ::close(fd);
    return ParseCsvImpl(ReadFileText(path, kMaxCsvFileBytes), path, 0, wanted);
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) return ParseCsvImpl(ReadFileText(path, kMaxCsvFileBytes), path, 0, wanted);
  ::madvise(map, size, MADV_SEQUENTIAL);
  struct Unmap {
    void* p;
    std::size_t n;
    ~Unmap() { ::munmap(p, n); }
  } unmap{map, size};
  return ParseCsvImpl(std::string_view(static_cast<const char*>(map), size), path, 0, wanted);
}

}  // namespace

CsvTable ReadCsv(const std::string& path) { return ReadCsvImpl(path, nullptr); }

CsvTable ReadCsvColumns(const std::string& path, const CsvColumns& wanted) {
  return ReadCsvImpl(path, &wanted);
}

}  // namespace vibid
