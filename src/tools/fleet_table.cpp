#include "fleet_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "batch_runner.h"
#include "cvg_bench/core/common/errors.h"
#include "json_fields.h"

namespace cvg_bench {
namespace tools {
namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

namespace {

/// The estimate part of a record's JSON: `final` of explain, the whole of identify.
const nlohmann::json& estimateOf(const nlohmann::json& result) {
  if (result.contains("final") && result["final"].is_object()) return result["final"];
  return result;
}

bool nonEmptyArray(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_array() && !j[key].empty();
}

std::string joined(const nlohmann::json& arr, const char* sep) {
  std::string s;
  if (!arr.is_array()) return s;
  for (const auto& v : arr) {
    if (!s.empty()) s += sep;
    s += v.is_string() ? v.get<std::string>() : v.dump();
  }
  return s;
}

std::string verdictOf(const nlohmann::json& status, const nlohmann::json& result) {
  if (intField(status, "exit_status", 1) != 0 || !result.is_object()) return "failed";
  if (result.contains("unexplained"))
    return boolField(result, "unexplained", true) ? "unexplained" : "explained";
  const nlohmann::json& e = estimateOf(result);
  const bool flagged = !boolField(e, "adequate", true) || nonEmptyArray(e, "flags") ||
                       nonEmptyArray(e, "not_identified") || nonEmptyArray(e, "unidentifiable");
  return flagged ? "flagged" : "ok";
}

std::string csvField(const ojson& v) {
  std::string s;
  if (v.is_null()) return "";
  if (v.is_string()) {
    s = v.get<std::string>();
  } else if (v.is_number_float()) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.10g", v.get<double>());
    s = buf;
  } else {
    s = v.dump();
  }
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

/// Flattens a row for the CSV: an estimate {value, ci_low, ci_high} becomes name, name_ci_low,
/// name_ci_high.
void flatten(const ojson& row, std::vector<std::pair<std::string, ojson>>& out) {
  for (auto it = row.begin(); it != row.end(); ++it) {
    if (it.key() == "columns") {
      for (auto c = it->begin(); c != it->end(); ++c) out.emplace_back(c.key(), *c);
    } else if (it->is_object() && it->contains("value")) {
      out.emplace_back(it.key(), (*it)["value"]);
      out.emplace_back(it.key() + "_ci_low", it->value("ci_low", ojson()));
      out.emplace_back(it.key() + "_ci_high", it->value("ci_high", ojson()));
    } else {
      out.emplace_back(it.key(), *it);
    }
  }
}

}  // namespace

ojson fleetRow(const FleetEntry& e, const FleetRowExtension& extend) {
  ojson row;
  row["record"] = stringField(e.status, "record");
  row["input"] = stringField(e.status, "input");
  row["columns"] = ojson::object();
  if (e.status.contains("columns") && e.status["columns"].is_object())
    for (auto c = e.status["columns"].begin(); c != e.status["columns"].end(); ++c)
      if (c->is_string()) row["columns"][c.key()] = *c;
  row["exit_status"] = intField(e.status, "exit_status", 1);
  row["verdict"] = verdictOf(e.status, e.result);
  row["message"] = stringField(e.status, "message");
  row["json"] = stringField(e.status, "json");
  if (!e.result.is_object()) return row;
  const nlohmann::json& est = estimateOf(e.result);
  if (e.result.contains("selected") && e.result["selected"].is_array())
    row["model"] = std::string("linear") + (e.result["selected"].empty() ? "" : "+") +
                   joined(e.result["selected"], "+");
  else
    row["model"] = stringField(est, "model");
  row["flags"] = est.contains("flags") ? joined(est["flags"], ";") : "";
  if (est.contains("not_identified") && est["not_identified"].is_array())
    row["not_identified"] = joined(est["not_identified"], ";");
  if (est.contains("frequency_hz") && est["frequency_hz"].is_number())
    row["frequency_hz"] = est["frequency_hz"];
  else if (est.contains("omega") && est["omega"].is_number())
    row["frequency_hz"] = est["omega"].get<double>() / (2 * M_PI);
  if (extend) extend(e.result, row);
  if (est.contains("derived_ci") && est["derived_ci"].is_object())
    for (auto it = est["derived_ci"].begin(); it != est["derived_ci"].end(); ++it) {
      if (!it->is_object() || !it->contains("value")) continue;
      ojson v;
      for (const char* k : {"value", "std", "ci_low", "ci_high"})
        if (it->contains(k)) v[k] = (*it)[k];
      row[it.key()] = v;
    }
  return row;
}

void writeFleetTable(std::vector<FleetEntry> entries, size_t record_count,
                     const std::vector<size_t>& expected, const std::string& dir,
                     const std::string& stem, const FleetRowExtension& extend) {
  std::sort(entries.begin(), entries.end(), [](const FleetEntry& a, const FleetEntry& b) {
    return intField(a.status, "index", 0) < intField(b.status, "index", 0);
  });
  std::vector<std::string> columns;
  std::set<std::string> seen;
  std::vector<std::vector<std::pair<std::string, ojson>>> flat;
  ojson records = ojson::array();
  std::set<size_t> present;
  size_t failed = 0;
  for (const auto& e : entries) {
    const ojson row = fleetRow(e, extend);
    records.push_back(row);
    present.insert(static_cast<size_t>(intField(e.status, "index", 0)));
    if (row["exit_status"] != 0) ++failed;
    flat.emplace_back();
    flatten(row, flat.back());
    for (const auto& kv : flat.back())
      if (seen.insert(kv.first).second) columns.push_back(kv.first);
  }
  std::ofstream csv(dir + "/" + stem + ".csv", std::ios::trunc);
  for (size_t c = 0; c < columns.size(); ++c) csv << (c ? "," : "") << columns[c];
  csv << "\n";
  for (const auto& r : flat) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (c) csv << ",";
      for (const auto& kv : r)
        if (kv.first == columns[c]) {
          csv << csvField(kv.second);
          break;
        }
    }
    csv << "\n";
  }
  if (!csv) throw InputError(dir + "/" + stem + ".csv: cannot write");
  ojson missing = ojson::array();
  for (size_t i : expected)
    if (!present.count(i)) missing.push_back(i);
  ojson j;
  j["record_count"] = record_count;
  j["present"] = entries.size();
  j["failed"] = failed;
  j["missing_indices"] = missing;
  j["records"] = records;
  std::ofstream js(dir + "/" + stem + ".json", std::ios::trunc);
  js << j.dump(1) << "\n";
  if (!js) throw InputError(dir + "/" + stem + ".json: cannot write");
}

std::vector<FleetEntry> readFleetEntries(const std::string& dir) {
  std::vector<FleetEntry> out;
  const fs::path records = fs::path(dir) / "records";
  if (!fs::is_directory(records)) return out;
  std::vector<fs::path> files;
  for (const auto& f : fs::directory_iterator(records)) {
    const std::string n = f.path().filename().string();
    if (n.size() > 12 && n.compare(n.size() - 12, 12, ".status.json") == 0)
      files.push_back(f.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    FleetEntry e;
    e.status = readBatchStatus(f.string());
    if (e.status.empty()) continue;
    const std::string js = stringField(e.status, "json");
    if (!js.empty()) {
      std::ifstream in(records / js);
      e.result = nlohmann::json::parse(in, nullptr, false);
      if (e.result.is_discarded()) e.result = nullptr;
    }
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace tools
}  // namespace cvg_bench
