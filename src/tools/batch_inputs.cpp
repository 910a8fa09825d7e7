#include "batch_inputs.h"

#include <glob.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "cvg_bench/core/common/errors.h"

namespace cvg_bench {
namespace tools {
namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;  // FNV-1a 64 (Fowler-Noll-Vo)
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

std::uint64_t fnv(std::uint64_t h, const char* p, size_t n) {
  for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<unsigned char>(p[i])) * kFnvPrime;
  return h;
}

std::string hex(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

/// The header fields of a manifest (empty when `path` is not a CSV naming a path column).
std::vector<std::string> manifestHeader(const std::string& path, int& header_line) {
  if (fs::path(path).extension() != ".csv" || !fs::is_regular_file(path)) return {};
  std::ifstream in(path);
  std::string line;
  header_line = 0;
  while (std::getline(in, line)) {
    ++header_line;
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    std::vector<std::string> fields = splitCsvLine(line);
    for (auto& f : fields) f = trim(f);
    for (const auto& f : fields)
      if (f == "path" || f == "input") return fields;
    return {};
  }
  return {};
}

void readManifest(const std::string& manifest, const std::vector<std::string>& header,
                  int header_line, std::vector<BatchRecord>& out) {
  size_t path_col = header.size();
  std::set<std::string> seen;
  for (size_t c = 0; c < header.size(); ++c) {
    if (header[c].empty())
      throw InputError(manifest + ":" + std::to_string(header_line) + ": column " +
                       std::to_string(c + 1) + " has no name");
    if (!seen.insert(header[c]).second)
      throw InputError(manifest + ":" + std::to_string(header_line) + ": column '" + header[c] +
                       "' named twice");
    if ((header[c] == "path" || header[c] == "input") && path_col == header.size()) path_col = c;
  }
  const fs::path base = fs::path(manifest).parent_path();
  std::ifstream in(manifest);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    if (++n <= header_line || trim(line).empty() || trim(line)[0] == '#') continue;
    const std::vector<std::string> fields = splitCsvLine(line);
    const std::string where = manifest + ":" + std::to_string(n);
    if (fields.size() != header.size())
      throw InputError(where + ": " + std::to_string(fields.size()) + " fields, the header has " +
                       std::to_string(header.size()));
    BatchRecord r;
    r.input = trim(fields[path_col]);
    if (r.input.empty()) throw InputError(where + ": field '" + header[path_col] + "' is empty");
    if (fs::path(r.input).is_relative() && !base.empty()) r.input = (base / r.input).string();
    for (size_t c = 0; c < header.size(); ++c)
      if (c != path_col) r.columns.emplace_back(header[c], trim(fields[c]));
    out.push_back(std::move(r));
  }
}

bool isPattern(const std::string& s) {
  return s.find_first_of("*?[") != std::string::npos && !fs::exists(s);
}

}  // namespace

std::string BatchRecord::column(const std::string& key) const {
  for (const auto& kv : columns)
    if (kv.first == key) return kv.second;
  return "";
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

std::vector<BatchRecord> expandBatchInputs(const std::vector<std::string>& positionals) {
  std::vector<BatchRecord> out;
  for (const auto& p : positionals) {
    int header_line = 0;
    const std::vector<std::string> header = manifestHeader(p, header_line);
    if (!header.empty()) {
      readManifest(p, header, header_line, out);
    } else if (isPattern(p)) {
      glob_t g{};
      if (::glob(p.c_str(), 0, nullptr, &g) == 0)
        for (size_t i = 0; i < g.gl_pathc; ++i)
          out.push_back(BatchRecord{0, g.gl_pathv[i], "", {}});
      globfree(&g);
    } else {
      out.push_back(BatchRecord{0, p, "", {}});
    }
  }
  if (out.empty()) throw InputError("batch: no records (the inputs and patterns matched nothing)");
  // Output names: the file's stem, made unique over the whole list (before sharding, so that every
  // shard names a record alike) by the record's position.
  std::map<std::string, int> stems;
  for (const auto& r : out) ++stems[fs::path(r.input).stem().string()];
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].index = i;
    std::string stem = fs::path(out[i].input).stem().string();
    if (stem.empty()) stem = "record";
    out[i].name = stems[stem] > 1 ? stem + "_" + std::to_string(i + 1) : stem;
  }
  return out;
}

Shard parseShard(const std::string& text) {
  const auto slash = text.find('/');
  Shard s;
  char* end = nullptr;
  if (slash != std::string::npos) {
    const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
    s.index = std::strtol(a.c_str(), &end, 10);
    const bool ok_a = !a.empty() && *end == '\0';
    s.count = std::strtol(b.c_str(), &end, 10);
    if (ok_a && !b.empty() && *end == '\0' && s.count >= 1 && s.index >= 0 && s.index < s.count)
      return s;
  }
  throw InputError("--shard needs I/N with 0 <= I < N (shards are numbered from 0), got '" + text +
                   "'");
}

Shard shardFromEnvironment(std::string& source) {
  const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
  if (!id || !count) {
    source = "";
    return Shard{};
  }
  const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
  const long i = std::atol(id) - (min ? std::atol(min) : 0);
  source = "Slurm job array (SLURM_ARRAY_TASK_ID " + std::string(id) + ", SLURM_ARRAY_TASK_MIN " +
           (min ? min : "unset") + ", SLURM_ARRAY_TASK_COUNT " + count + ")";
  return parseShard(std::to_string(i) + "/" + count);
}

std::string hashFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "unreadable";
  std::uint64_t h = kFnvOffset;
  char buf[1 << 16];
  while (in) {
    in.read(buf, sizeof buf);
    h = fnv(h, buf, static_cast<size_t>(in.gcount()));
  }
  return hex(h);
}

std::string hashString(const std::string& text) {
  return hex(fnv(kFnvOffset, text.data(), text.size()));
}

}  // namespace tools
}  // namespace cvg_bench
