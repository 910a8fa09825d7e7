// The fleet table of `cvg_ident batch` (docs/fleet.md): one row per record from its status file and
// its identify/explain JSON — manifest columns, exit status, verdict, model, flags, frequency and
// every `derived_ci` quantity (value and interval) the JSON holds — written as fleet.csv and
// fleet.json. Rows in record order and columns in order of first appearance, so that one run and
// merged shards give identical tables.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace cvg_bench {
namespace tools {

struct FleetEntry {
  nlohmann::json status;  ///< DIR/records/NAME.status.json
  nlohmann::json result;  ///< the record's JSON (null when it failed)
};

/// Adds columns computed from a record's JSON (e.g. fleet_drift.h); may be empty.
using FleetRowExtension =
    std::function<void(const nlohmann::json& result, nlohmann::ordered_json& row)>;

/// One row (ordered keys; estimates as {value, std, ci_low, ci_high}).
nlohmann::ordered_json fleetRow(const FleetEntry& e, const FleetRowExtension& extend = {});

/// Writes `<stem>.csv` and `<stem>.json` in dir; entries sorted by their index first.
/// `record_count` is the length of the whole list; `expected` the indices this table should hold
/// (those without a row are listed in the JSON as missing).
void writeFleetTable(std::vector<FleetEntry> entries, size_t record_count,
                     const std::vector<size_t>& expected, const std::string& dir,
                     const std::string& stem, const FleetRowExtension& extend = {});

/// Reads every complete DIR/records/*.status.json (and each JSON of a record that succeeded).
std::vector<FleetEntry> readFleetEntries(const std::string& dir);

}  // namespace tools
}  // namespace cvg_bench
