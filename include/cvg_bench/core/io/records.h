// In-memory records: what the simulator writes, the demodulator reads and writes, and the
// estimators consume. One struct per kind of file of interfaces.md "Input files":
//   SlowRecord   free decay, slow variables q = (q1, p1, q2, p2) of (2.4) at times t
//   (t,q1,p1,q2,p2) SweepRecord  forced sweep, stationary q per drive frequency omega0
//   (omega0,q1,...) RawRecord    raw generalized coordinates f, g of (2.3) at times t (t,f,g)
// Amplitudes are in the record's units; times in s; frequencies in rad/s.
// Metadata are the file's `# key: value` lines (known keys: omega, mode; the simulator adds
// truth_<parameter> lines with the true parameter values).
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace cvg_bench {

/// Which of the three record layouts a file holds.
enum class RecordKind { kFreeDecay, kForcedSweep, kRaw };

/// "free_decay", "forced" or "raw".
std::string recordKindName(RecordKind kind);

/// The `# key: value` lines of a file, by key (a repeated key: the last one wins).
using RecordMetadata = std::map<std::string, std::string>;

/// Extra numeric columns beyond the required ones, by header name, one value per row.
using ExtraColumns = std::map<std::string, std::vector<double>>;

/// Free-decay record of the slow variables (section 2): q(t_i), i = 0..N.
struct SlowRecord {
  std::vector<double> t_s;         ///< sample times [s], strictly increasing
  std::vector<Eigen::Vector4d> q;  ///< (q1, p1, q2, p2) per sample [amplitude units]
  double omega_rad_s = 0.0;        ///< natural frequency omega [rad/s]; 0 when unknown
  RecordMetadata metadata;         ///< all `# key: value` lines (omega and mode included)
  ExtraColumns extra;              ///< other columns of the file, kept by name
  std::string source;              ///< file name (for messages); empty when built in memory
  size_t size() const { return t_s.size(); }
};

/// Forced sweep (section 3): stationary slow variables at drive frequencies omega0_j.
/// Optional per-point flags (empty when absent from the file):
///   direction: +1 for a point of an up-sweep (omega0 increasing), -1 for a down-sweep;
///   jump: 1 when the point was reached by a jump to another branch of a bistable (folded)
///         response, i.e. it is not on the continuation of the previous point's branch.
struct SweepRecord {
  std::vector<double> omega0_rad_s;  ///< drive frequency omega0 = omega + lambda [rad/s], > 0
  std::vector<Eigen::Vector4d> q;    ///< stationary (q1, p1, q2, p2) [amplitude units]
  std::vector<int> direction;        ///< +1 up / -1 down per point, or empty
  std::vector<int> jump;             ///< 1 = branch jump at this point, or empty
  double omega_rad_s = 0.0;          ///< natural frequency omega [rad/s]; 0 when unknown
  RecordMetadata metadata;
  ExtraColumns extra;
  std::string source;
  size_t size() const { return omega0_rad_s.size(); }
};

/// Raw signals f(t), g(t) of the full equations (2.3)/(3.1); uniform or irregular sampling.
/// A forced raw record (the simulator's `--mode forced --raw`) also carries an `omega0` column
/// (in extra): the drive frequency of the settled sweep step each sample belongs to.
struct RawRecord {
  std::vector<double> t_s;   ///< sample times [s], strictly increasing after reading
  std::vector<double> f, g;  ///< generalized coordinates [amplitude units]
  double omega_rad_s = 0.0;  ///< natural frequency omega [rad/s]; 0 when unknown
  RecordMetadata metadata;
  ExtraColumns extra;
  std::string source;
  /// Set by the reader when asked to repair timestamps (RecordReadOptions::repair_raw_timestamps):
  int n_reordered = 0;           ///< rows that arrived earlier than a previous row and were sorted
  int n_duplicates_dropped = 0;  ///< rows dropped because their time equals an earlier row's
  size_t size() const { return t_s.size(); }
};

}  // namespace cvg_bench
