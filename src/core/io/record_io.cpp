#include "cvg_bench/core/io/record_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <set>
#include <sstream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/number_text.h"
#include "cvg_bench/core/io/input_checks.h"

namespace cvg_bench {

bool parseFiniteNumber(const std::string& s, double* value) {
  double v = 0.0;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || res.ec != std::errc() || res.ptr != s.data() + s.size() || !std::isfinite(v))
    return false;
  *value = v;
  return true;
}

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

/// Cells of one row as [begin, end) offsets into the line (no allocation per cell).
void splitCells(const std::string& line, char sep, std::vector<std::pair<size_t, size_t>>& cells) {
  cells.clear();
  size_t start = 0;
  for (size_t i = 0; i <= line.size(); ++i) {
    if (i == line.size() || line[i] == sep) {
      size_t b = start, e = i;
      while (b < e && (line[b] == ' ' || line[b] == '\t')) ++b;
      while (e > b && (line[e - 1] == ' ' || line[e - 1] == '\t' || line[e - 1] == '\r')) --e;
      cells.emplace_back(b, e);
      start = i + 1;
    }
  }
}

/// A parsed table: metadata, header names and numeric rows (column-major), with line numbers.
struct Table {
  std::string source;
  RecordMetadata metadata;
  std::map<std::string, int> metadata_line;
  std::vector<std::string> header;
  int header_line = 0;
  std::vector<std::vector<double>> columns;
  std::vector<int> row_line;  ///< 1-based line number of each data row

  std::string where(int line, int column = 0) const {
    std::string s = source + ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
    return s + ": ";
  }
  int columnIndex(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  }
  bool hasAll(const std::vector<std::string>& names) const {
    for (const auto& n : names)
      if (columnIndex(n) < 0) return false;
    return true;
  }
  /// Locator of data row r (and a column by name) for the range checks.
  RowLocator locator() const {
    return [this](size_t r, const std::string& name) {
      return where(row_line[r], columnIndex(name) + 1);
    };
  }
  /// Magnitude checks of the named state columns (input_checks.h).
  void checkStates(const std::vector<std::string>& names) const {
    std::vector<std::pair<std::string, const std::vector<double>*>> cols;
    for (const auto& n : names) cols.emplace_back(n, &columns[columnIndex(n)]);
    checkStateColumns(cols, locator());
  }
};

Table parseTable(const std::string& text, const std::string& source) {
  Table table;
  table.source = source;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  char sep = ',';
  std::vector<std::pair<size_t, size_t>> cells;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] == '#') {
      if (!table.header.empty()) continue;  // comments after the header are ignored
      const std::string body = trim(t.substr(1));
      const auto colon = body.find(':');
      if (colon == std::string::npos) continue;  // a plain comment
      const std::string key = trim(body.substr(0, colon));
      if (key.empty()) continue;
      table.metadata[key] = trim(body.substr(colon + 1));
      table.metadata_line[key] = line_no;
      continue;
    }
    if (table.header.empty()) {
      sep = t.find(';') != std::string::npos ? ';' : ',';
      splitCells(t, sep, cells);
      std::set<std::string> seen;
      for (size_t c = 0; c < cells.size(); ++c) {
        const std::string name = t.substr(cells[c].first, cells[c].second - cells[c].first);
        if (name.empty())
          throw InputError(table.where(line_no, static_cast<int>(c + 1)) + "empty column name");
        if (!seen.insert(name).second)
          throw InputError(table.where(line_no, static_cast<int>(c + 1)) + "column '" + name +
                           "' appears twice in the header");
        table.header.push_back(name);
      }
      table.header_line = line_no;
      table.columns.assign(table.header.size(), {});
      continue;
    }
    splitCells(line, sep, cells);
    if (cells.size() != table.header.size())
      throw InputError(table.where(line_no) + "expected " + std::to_string(table.header.size()) +
                       " fields as in the header (line " + std::to_string(table.header_line) +
                       "), got " + std::to_string(cells.size()));
    for (size_t c = 0; c < cells.size(); ++c) {
      const char* b = line.data() + cells[c].first;
      const char* e = line.data() + cells[c].second;
      if (b < e && *b == '+') ++b;
      double v = 0.0;
      const auto res = std::from_chars(b, e, v);
      const bool bad = b == e || res.ec != std::errc() || res.ptr != e || !std::isfinite(v);
      if (bad) {
        const std::string cell = line.substr(cells[c].first, cells[c].second - cells[c].first);
        const std::string col =
            table.where(line_no, static_cast<int>(c + 1)) + "column '" + table.header[c] + "': ";
        if (b == e) throw InputError(col + "empty cell");
        if (res.ec != std::errc() || res.ptr != e)
          throw InputError(col + "'" + cell + "' is not a number");
        throw InputError(col + "'" + cell + "' is not finite");
      }
      table.columns[c].push_back(v);
    }
    table.row_line.push_back(line_no);
  }
  if (table.header.empty()) throw InputError(source + ": empty file (no header row)");
  if (table.row_line.empty())
    throw InputError(table.where(table.header_line) + "no data rows after the header");
  return table;
}

double metadataOmega(const Table& table) {
  const auto it = table.metadata.find("omega");
  if (it == table.metadata.end()) return 0.0;
  const std::string& s = it->second;
  double v = 0.0;
  if (!parseFiniteNumber(s, &v) || v <= 0.0)
    throw InputError(table.where(table.metadata_line.at("omega")) + "# omega: '" + s +
                     "' is not a positive number [rad/s]");
  requireOmegaInRange(v, table.where(table.metadata_line.at("omega")) + "# omega");
  return v;
}

const std::vector<std::string> kSlowColumns = {"t", "q1", "p1", "q2", "p2"};
const std::vector<std::string> kSweepColumns = {"omega0", "q1", "p1", "q2", "p2"};

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + v[i];
  return s;
}

RecordKind detectKind(const Table& table, const RawColumnMap& raw) {
  if (table.hasAll(kSweepColumns)) return RecordKind::kForcedSweep;
  if (table.hasAll(kSlowColumns)) return RecordKind::kFreeDecay;
  if (table.hasAll({raw.t, raw.f, raw.g})) return RecordKind::kRaw;
  throw InputError(table.where(table.header_line) + "header '" + joined(table.header) +
                   "' has none of the known column sets: free decay " + joined(kSlowColumns) +
                   "; forced sweep " + joined(kSweepColumns) + "; raw " + raw.t + "," + raw.f +
                   "," + raw.g + " (map other names with --columns t=COL,f=COL,g=COL)");
}

/// Strictly increasing times, else InputError at the offending row.
void requireIncreasing(const Table& table, int col) {
  const auto& t = table.columns[col];
  for (size_t i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) continue;
    throw InputError(table.where(table.row_line[i], col + 1) + "time " + printfGText(t[i], 17) +
                     (t[i] == t[i - 1] ? " repeats" : " is before") + " the previous row's " +
                     printfGText(t[i - 1], 17) + " (line " + std::to_string(table.row_line[i - 1]) +
                     "): timestamps must increase strictly");
  }
}

ExtraColumns extraColumns(const Table& table, const std::vector<std::string>& used) {
  ExtraColumns extra;
  for (size_t c = 0; c < table.header.size(); ++c) {
    if (std::find(used.begin(), used.end(), table.header[c]) == used.end())
      extra[table.header[c]] = table.columns[c];
  }
  return extra;
}

std::vector<Eigen::Vector4d> slowColumns(const Table& table) {
  const int i1 = table.columnIndex("q1"), i2 = table.columnIndex("p1"),
            i3 = table.columnIndex("q2"), i4 = table.columnIndex("p2");
  std::vector<Eigen::Vector4d> q(table.row_line.size());
  for (size_t r = 0; r < q.size(); ++r)
    q[r] = Eigen::Vector4d(table.columns[i1][r], table.columns[i2][r], table.columns[i3][r],
                           table.columns[i4][r]);
  return q;
}

SlowRecord toSlow(const Table& table) {
  const int it = table.columnIndex("t");
  requireIncreasing(table, it);
  checkTimeColumn(table.columns[it], "t", table.locator());
  table.checkStates({"q1", "p1", "q2", "p2"});
  SlowRecord r;
  r.t_s = table.columns[it];
  r.q = slowColumns(table);
  r.omega_rad_s = metadataOmega(table);
  r.metadata = table.metadata;
  r.extra = extraColumns(table, kSlowColumns);
  r.source = table.source;
  return r;
}

std::vector<int> flagColumn(const Table& table, const std::string& name,
                            const std::set<int>& allowed) {
  const int c = table.columnIndex(name);
  if (c < 0) return {};
  std::vector<int> out;
  for (size_t r = 0; r < table.row_line.size(); ++r) {
    const double v = table.columns[c][r];
    // Range check first: a flag like 7.8e27 is integral but no int (UB to convert).
    if (v != std::round(v) || std::abs(v) > 1e6 || !allowed.count(static_cast<int>(v)))
      throw InputError(table.where(table.row_line[r], c + 1) + "column '" + name +
                       "': " + printfGText(v, 17) + " is not one of the allowed flags");
    out.push_back(static_cast<int>(v));
  }
  return out;
}

SweepRecord toSweep(const Table& table) {
  const int io = table.columnIndex("omega0");
  for (size_t r = 0; r < table.row_line.size(); ++r) {
    if (table.columns[io][r] <= 0.0)
      throw InputError(table.where(table.row_line[r], io + 1) + "omega0 " +
                       printfGText(table.columns[io][r], 17) + " must be > 0 [rad/s]");
  }
  checkExcitationColumn(table.columns[io], "omega0", table.locator());
  table.checkStates({"q1", "p1", "q2", "p2"});
  SweepRecord s;
  s.omega0_rad_s = table.columns[io];
  s.q = slowColumns(table);
  s.direction = flagColumn(table, "direction", {-1, 1});
  s.jump = flagColumn(table, "jump", {0, 1});
  s.omega_rad_s = metadataOmega(table);
  s.metadata = table.metadata;
  std::vector<std::string> used = kSweepColumns;
  used.push_back("direction");
  used.push_back("jump");
  s.extra = extraColumns(table, used);
  s.source = table.source;
  return s;
}

RawRecord toRaw(const Table& table, const RecordReadOptions& options) {
  const RawColumnMap& m = options.raw_columns;
  const int it = table.columnIndex(m.t), jf = table.columnIndex(m.f), jg = table.columnIndex(m.g);
  RawRecord r;
  r.omega_rad_s = metadataOmega(table);
  r.metadata = table.metadata;
  r.source = table.source;
  ExtraColumns extra = extraColumns(table, {m.t, m.f, m.g});
  const size_t n = table.row_line.size();
  table.checkStates({m.f, m.g});
  if (!options.repair_raw_timestamps) {
    requireIncreasing(table, it);
    checkTimeColumn(table.columns[it], m.t, table.locator());
    r.t_s = table.columns[it];
    r.f = table.columns[jf];
    r.g = table.columns[jg];
    r.extra = std::move(extra);
    return r;
  }
  const auto& t = table.columns[it];
  double running_max = -INFINITY;
  for (size_t i = 0; i < n; ++i) {
    if (t[i] < running_max) ++r.n_reordered;
    running_max = std::max(running_max, t[i]);
  }
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return t[a] < t[b]; });
  for (auto& kv : extra) r.extra[kv.first].reserve(n);
  std::vector<size_t> kept;  // table row of each kept sample
  for (size_t k = 0; k < n; ++k) {
    const size_t i = order[k];
    if (!r.t_s.empty() && t[i] == r.t_s.back()) {
      ++r.n_duplicates_dropped;
      continue;
    }
    kept.push_back(i);
    r.t_s.push_back(t[i]);
    r.f.push_back(table.columns[jf][i]);
    r.g.push_back(table.columns[jg][i]);
    for (auto& kv : extra) r.extra[kv.first].push_back(kv.second[i]);
  }
  const RowLocator by_table_row = table.locator();
  checkTimeColumn(r.t_s, m.t,
                  [&](size_t k, const std::string& c) { return by_table_row(kept[k], c); });
  return r;
}

std::string readFile(const std::string& path) {
  requireInputFile(path, "input record");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeHeaderLines(std::ostream& out, double omega, const std::string& mode,
                      const RecordMetadata& metadata) {
  if (omega > 0.0) out << "# omega: " << printfGText(omega, 17) << "\n";
  out << "# mode: " << mode << "\n";
  for (const auto& kv : metadata) {
    if (kv.first == "omega" || kv.first == "mode") continue;
    out << "# " << kv.first << ": " << kv.second << "\n";
  }
}

void checkExtra(const ExtraColumns& extra, size_t n, const std::string& what) {
  for (const auto& kv : extra) {
    if (kv.second.size() != n)
      throw InputError(what + ": extra column '" + kv.first + "' has " +
                       std::to_string(kv.second.size()) + " values for " + std::to_string(n) +
                       " rows");
  }
}

/// Writes the header and rows; row(i, buf) appends the required cells of row i.
template <typename RowFn>
void writeRows(std::ostream& out, const std::string& header, const ExtraColumns& extra, size_t n,
               RowFn row) {
  out << header;
  for (const auto& kv : extra) out << "," << kv.first;
  out << "\n";
  std::string line;
  for (size_t i = 0; i < n; ++i) {
    line.clear();
    row(i, line);
    for (const auto& kv : extra) line += "," + printfGText(kv.second[i], 17);
    line += "\n";
    out << line;
  }
  if (!out) throw InputError("write failed");
}

void appendCells(std::string& line, std::initializer_list<double> v) {
  bool first = line.empty();
  char buf[40];
  for (double x : v) {
    if (!first) line += ',';
    first = false;
    std::snprintf(buf, sizeof(buf), "%.17g", x);
    line += buf;
  }
}

template <typename Rec, typename Writer>
void writeFile(const Rec& record, const std::string& path, Writer writer) {
  requireOutputFile(path, "output record");
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot open for writing");
  try {
    writer(record, out);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  out.close();
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace

std::string recordKindName(RecordKind kind) {
  switch (kind) {
    case RecordKind::kFreeDecay:
      return "free_decay";
    case RecordKind::kForcedSweep:
      return "forced";
    case RecordKind::kRaw:
      return "raw";
  }
  return "unknown";
}

RawColumnMap parseRawColumnMap(const std::string& spec) {
  RawColumnMap m;
  std::set<std::string> seen;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = trim(item);
    if (item.empty()) continue;
    auto eq = item.find('=');
    if (eq == std::string::npos) eq = item.find(':');
    if (eq == std::string::npos)
      throw InputError("--columns: '" + item + "' is not KEY=COLUMN (keys t, f, g)");
    const std::string key = trim(item.substr(0, eq)), col = trim(item.substr(eq + 1));
    if (col.empty()) throw InputError("--columns: empty column name for '" + key + "'");
    if (!seen.insert(key).second) throw InputError("--columns: key '" + key + "' given twice");
    if (key == "t") {
      m.t = col;
    } else if (key == "f") {
      m.f = col;
    } else if (key == "g") {
      m.g = col;
    } else {
      throw InputError("--columns: unknown key '" + key + "' (known: t, f, g)");
    }
  }
  return m;
}

double AnyRecord::omegaRadS() const {
  switch (kind) {
    case RecordKind::kFreeDecay:
      return slow.omega_rad_s;
    case RecordKind::kForcedSweep:
      return sweep.omega_rad_s;
    case RecordKind::kRaw:
      return raw.omega_rad_s;
  }
  return 0.0;
}

const RecordMetadata& AnyRecord::metadata() const {
  switch (kind) {
    case RecordKind::kForcedSweep:
      return sweep.metadata;
    case RecordKind::kRaw:
      return raw.metadata;
    default:
      return slow.metadata;
  }
}

namespace {

std::string lowered(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// A position track written without --columns (a camera's `time;x;y`): the header's time column
/// (t, time, time_s, timestamp) and one coordinate pair (x,y or f,g), case ignored, become t, f, g,
/// in a header of exactly those three columns.
/// Only for a header that is no known column set and no --columns map; nothing else is guessed.
bool positionTrackColumns(const Table& table, RawColumnMap* map, std::string* note) {
  if (table.header.size() != 3) return false;  // t,x,y,z is not guessed: which pair is meant?
  std::string t, f, g;
  for (const auto& h : table.header) {
    const std::string l = lowered(h);
    if (t.empty() && (l == "t" || l == "time" || l == "time_s" || l == "timestamp")) t = h;
  }
  for (const auto& pair : {std::make_pair("x", "y"), std::make_pair("f", "g")}) {
    for (const auto& h : table.header) {
      if (f.empty() && lowered(h) == pair.first) f = h;
      if (g.empty() && lowered(h) == pair.second) g = h;
    }
    if (!f.empty() && !g.empty()) break;
    f.clear();
    g.clear();
  }
  if (t.empty() || f.empty() || g.empty()) return false;
  map->t = t;
  map->f = f;
  map->g = g;
  *note = "columns " + t + ", " + f + ", " + g + " read as t, f, g (a position track; --columns " +
          "maps other names)";
  return true;
}

bool isDefaultMap(const RawColumnMap& m) {
  return m.t == "t" && m.f == "f" && m.g == "g";
}

}  // namespace

AnyRecord readRecordCsvText(const std::string& text, const std::string& source_name,
                            const RecordReadOptions& options) {
  const Table table = parseTable(text, source_name);
  AnyRecord rec;
  RecordReadOptions o = options;
  std::string columns_note;
  if (isDefaultMap(options.raw_columns) && !table.hasAll(kSweepColumns) &&
      !table.hasAll(kSlowColumns) && !table.hasAll({"t", "f", "g"}))
    positionTrackColumns(table, &o.raw_columns, &columns_note);
  rec.kind = detectKind(table, o.raw_columns);
  switch (rec.kind) {
    case RecordKind::kFreeDecay:
      rec.slow = toSlow(table);
      break;
    case RecordKind::kForcedSweep:
      rec.sweep = toSweep(table);
      break;
    case RecordKind::kRaw:
      rec.raw = toRaw(table, o);
      if (!columns_note.empty()) rec.raw.metadata["columns_read_as"] = columns_note;
      break;
  }
  return rec;
}

AnyRecord readRecordCsv(const std::string& path, const RecordReadOptions& options) {
  return readRecordCsvText(readFile(path), path, options);
}

namespace {
AnyRecord readExpecting(const std::string& path, RecordKind kind, const RecordReadOptions& o) {
  AnyRecord rec = readRecordCsv(path, o);
  if (rec.kind != kind)
    throw InputError(path + ": expected a " + recordKindName(kind) + " record, the header says " +
                     recordKindName(rec.kind));
  return rec;
}
}  // namespace

SlowRecord readSlowRecordCsv(const std::string& path) {
  return readExpecting(path, RecordKind::kFreeDecay, {}).slow;
}

SweepRecord readSweepRecordCsv(const std::string& path) {
  return readExpecting(path, RecordKind::kForcedSweep, {}).sweep;
}

RawRecord readRawRecordCsv(const std::string& path, const RecordReadOptions& options) {
  return readExpecting(path, RecordKind::kRaw, options).raw;
}

void writeSlowRecordCsv(const SlowRecord& r, std::ostream& out) {
  if (r.q.size() != r.t_s.size())
    throw InputError("slow record: " + std::to_string(r.t_s.size()) + " times but " +
                     std::to_string(r.q.size()) + " states");
  checkExtra(r.extra, r.size(), "slow record");
  writeHeaderLines(out, r.omega_rad_s, "free_decay", r.metadata);
  writeRows(out, "t,q1,p1,q2,p2", r.extra, r.size(), [&](size_t i, std::string& line) {
    appendCells(line, {r.t_s[i], r.q[i][0], r.q[i][1], r.q[i][2], r.q[i][3]});
  });
}

void writeSweepRecordCsv(const SweepRecord& r, std::ostream& out) {
  const size_t n = r.size();
  if (r.q.size() != n || (!r.direction.empty() && r.direction.size() != n) ||
      (!r.jump.empty() && r.jump.size() != n))
    throw InputError("sweep record: columns of different lengths");
  checkExtra(r.extra, n, "sweep record");
  writeHeaderLines(out, r.omega_rad_s, "forced", r.metadata);
  std::string header = "omega0,q1,p1,q2,p2";
  if (!r.direction.empty()) header += ",direction";
  if (!r.jump.empty()) header += ",jump";
  writeRows(out, header, r.extra, n, [&](size_t i, std::string& line) {
    appendCells(line, {r.omega0_rad_s[i], r.q[i][0], r.q[i][1], r.q[i][2], r.q[i][3]});
    if (!r.direction.empty()) line += "," + std::to_string(r.direction[i]);
    if (!r.jump.empty()) line += "," + std::to_string(r.jump[i]);
  });
}

void writeRawRecordCsv(const RawRecord& r, std::ostream& out) {
  if (r.f.size() != r.t_s.size() || r.g.size() != r.t_s.size())
    throw InputError("raw record: t, f, g have different lengths");
  checkExtra(r.extra, r.size(), "raw record");
  const auto mode = r.metadata.find("mode");
  writeHeaderLines(out, r.omega_rad_s, mode == r.metadata.end() ? "free_decay" : mode->second,
                   r.metadata);
  writeRows(out, "t,f,g", r.extra, r.size(), [&](size_t i, std::string& line) {
    appendCells(line, {r.t_s[i], r.f[i], r.g[i]});
  });
}

void writeSlowRecordCsv(const SlowRecord& record, const std::string& path) {
  writeFile(record, path, [](const SlowRecord& r, std::ostream& o) { writeSlowRecordCsv(r, o); });
}

void writeSweepRecordCsv(const SweepRecord& record, const std::string& path) {
  writeFile(record, path, [](const SweepRecord& r, std::ostream& o) { writeSweepRecordCsv(r, o); });
}

void writeRawRecordCsv(const RawRecord& record, const std::string& path) {
  writeFile(record, path, [](const RawRecord& r, std::ostream& o) { writeRawRecordCsv(r, o); });
}

}  // namespace cvg_bench
