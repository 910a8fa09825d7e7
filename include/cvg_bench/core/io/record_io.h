// CSV reading and writing of records (interfaces.md "Input files").
//
// Format: optional `# key: value` lines, then a header row, then one row per sample; cells
// separated by `,` or `;` (decided by the header row), surrounding blanks ignored, blank lines and
// later `#` lines skipped. Columns are found by header name, in any order; other columns are kept
// in the record's `extra` map. The kind is detected from the header:
//   omega0,q1,p1,q2,p2 -> forced sweep;  t,q1,p1,q2,p2 -> free decay;  t,f,g (or mapped) -> raw.
// Every problem is an InputError whose message starts with "file:line:column:" (column = 1-based
// field number) where it applies: a cell that is not a finite number, a wrong number of fields,
// missing columns, an empty file or no data rows, non-increasing or duplicated timestamps.
// Raw records may instead be repaired (sorted, duplicates dropped, counts kept in the record).
// Writers use full double precision (%.17g) and write `# omega:` and `# mode:` first.
#pragma once

#include <iosfwd>
#include <string>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

/// Header names of the raw columns (for `--columns t=time,f=x,g=y`).
struct RawColumnMap {
  std::string t = "t";  ///< time column [s]
  std::string f = "f";  ///< first generalized coordinate
  std::string g = "g";  ///< second generalized coordinate
};

/// Parses "t=COL,f=COL,g=COL" (any subset, any order; ':' also accepted for '='). InputError on
/// unknown keys, empty names or repeated keys.
RawColumnMap parseRawColumnMap(const std::string& spec);

/// The whole of s as one finite number (no sign of trailing text, no inf/nan); false otherwise.
/// Metadata values of `# key: value` lines are read with it.
bool parseFiniteNumber(const std::string& s, double* value);

struct RecordReadOptions {
  /// Header names of the raw record's t, f, g columns.
  RawColumnMap raw_columns;
  /// Raw records only: sort rows that arrive out of time order and drop rows whose time repeats an
  /// earlier row (counted in RawRecord::n_reordered / n_duplicates_dropped) instead of failing.
  /// Slow (free decay) records are always strict.
  bool repair_raw_timestamps = false;
};

/// A record of any kind as read from a file: `kind` says which member is filled.
struct AnyRecord {
  RecordKind kind = RecordKind::kFreeDecay;
  SlowRecord slow;
  SweepRecord sweep;
  RawRecord raw;
  /// omega [rad/s] of whichever record is filled (0 when unknown).
  double omegaRadS() const;
  const RecordMetadata& metadata() const;
};

/// Reads a CSV file of any kind (detected from the header).
AnyRecord readRecordCsv(const std::string& path, const RecordReadOptions& options = {});
/// The same from a string; source_name is used in messages in place of the file name.
AnyRecord readRecordCsvText(const std::string& text, const std::string& source_name,
                            const RecordReadOptions& options = {});

/// Per-kind readers: an InputError when the file holds another kind.
SlowRecord readSlowRecordCsv(const std::string& path);
SweepRecord readSweepRecordCsv(const std::string& path);
RawRecord readRawRecordCsv(const std::string& path, const RecordReadOptions& options = {});

/// Writers. `# omega:` (when > 0) and `# mode:` come first (mode from metadata["mode"] for raw
/// records, default free_decay; fixed for slow and sweep records), then the other metadata keys,
/// the header and the rows; extra columns follow the required ones. Sizes must agree (InputError).
void writeSlowRecordCsv(const SlowRecord& record, std::ostream& out);
void writeSweepRecordCsv(const SweepRecord& record, std::ostream& out);
void writeRawRecordCsv(const RawRecord& record, std::ostream& out);
/// File versions: InputError when the file cannot be written.
void writeSlowRecordCsv(const SlowRecord& record, const std::string& path);
void writeSweepRecordCsv(const SweepRecord& record, const std::string& path);
void writeRawRecordCsv(const RawRecord& record, const std::string& path);

}  // namespace cvg_bench
