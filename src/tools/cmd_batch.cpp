// `cvg_ident batch`: many records through the identify/explain pipeline, resumable and sharded,
// with a fleet table (docs/fleet.md). Each record runs as its own cvg_ident process
// (batch_runner.h).
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>

#include "batch_inputs.h"
#include "batch_runner.h"
#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/package_resources.h"
#include "cvg_ident_commands.h"
#include "fleet_drift.h"
#include "fleet_table.h"
#include "json_fields.h"

namespace cvg_bench {
namespace tools {
namespace fs = std::filesystem;

namespace {

const char* kHelp =
    "usage: cvg_ident batch INPUT... | MANIFEST.csv --mode MODE [--explain] [OPTIONS OF THE "
    "COMMAND]\n"
    "                       [--jobs N] [--shard I/N] [--timeout S] [--force] [--reports]\n"
    "                       [--no-plots] --out DIR\n"
    "       cvg_ident batch --merge DIR [--merge DIR ...] --out DIR [--no-plots]\n"
    "Runs `cvg_ident identify` (or `explain` with --explain) on every record, each as its own\n"
    "process, and writes DIR/records/NAME.json (the command's JSON), NAME.log (its output) and\n"
    "NAME.status.json (exit status, message, hashes, time, peak memory), then the fleet table\n"
    "DIR/fleet.csv and DIR/fleet.json and the fleet report (DIR/fleet.md, PNGs). See "
    "docs/fleet.md.\n"
    "  INPUT            record files or glob patterns; or a manifest: a CSV whose header names a\n"
    "                   `path` column (relative paths from the manifest's folder); its other "
    "columns\n"
    "                   are carried into the fleet table. A `mode` column overrides --mode per\n"
    "                   record; with --mode ringdown a `frequency_hz` column is passed as "
    "--frequency.\n"
    "  --mode MODE      free_decay, forced, ringdown or response (as for identify/explain)\n"
    "  --explain        run explain instead of identify\n"
    "  other options    passed to every identify/explain call (e.g. --model linear, --confidence)\n"
    "  --jobs N         records analysed at once (default 1); results do not depend on N\n"
    "  --shard I/N      only the records with index % N == I (0 <= I < N); without it a Slurm job\n"
    "                   array's SLURM_ARRAY_TASK_ID/_MIN/_COUNT are used when set. A shard writes\n"
    "                   DIR/fleet_shard_I_of_N.{csv,json}; join shards with --merge.\n"
    "  --timeout S      kill a record's analysis after S seconds (listed as failed, retried on "
    "rerun)\n"
    "  --force          rerun records already done\n"
    "  --reports        with --explain: each record's report in DIR/records/NAME_report/\n"
    "  --no-plots       fleet table only (no fleet.md and PNGs)\n"
    "  --merge DIR      join the records/ of shard output folders into --out\n"
    "A rerun skips records whose status file is complete with the same input content and settings\n"
    "(hashes), so a killed batch resumes. Exit status: 0 when every record has an outcome (a "
    "record's\n"
    "own failure is an outcome, listed in fleet.csv with its exit status and message); 1 when a\n"
    "record crashed or timed out, or (merge) records are missing; 2 bad usage.\n";

const std::set<std::string> kBatchValueOptions = {"mode", "jobs",    "shard",
                                                  "out",  "timeout", "merge"};
const std::set<std::string> kBatchFlags = {"explain", "force", "reports", "no-plots", "help"};
// identify/explain options that take no value; every other forwarded option takes one.
const std::set<std::string> kForwardedFlags = {"no-figures"};
const std::set<std::string> kManagedOptions = {"json", "report"};

struct BatchArgs {
  std::map<std::string, std::vector<std::string>> own;
  std::set<std::string> flags;
  std::vector<std::string> positionals, forwarded;
  std::string get(const std::string& k, const std::string& fb = "") const {
    auto it = own.find(k);
    return it == own.end() ? fb : it->second.back();
  }
};

BatchArgs parse(const std::vector<std::string>& argv) {
  BatchArgs a;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& s = argv[i];
    if (s == "-h") {
      a.flags.insert("help");
      continue;
    }
    if (s.rfind("--", 0) != 0 || s.size() == 2) {
      a.positionals.push_back(s);
      continue;
    }
    std::string key = s.substr(2), val;
    const auto eq = key.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) {
      val = key.substr(eq + 1);
      key = key.substr(0, eq);
    }
    if (kBatchFlags.count(key) || kForwardedFlags.count(key)) {
      if (inline_value) throw InputError("option --" + key + " takes no value");
      if (kBatchFlags.count(key))
        a.flags.insert(key);
      else
        a.forwarded.push_back(s);
      continue;
    }
    if (kManagedOptions.count(key))
      throw InputError("batch writes each record's --" + key +
                       " itself (DIR/records/); give --out DIR" +
                       (key == "report" ? " and --reports" : ""));
    if (!inline_value) {
      if (i + 1 >= argv.size()) throw InputError("option --" + key + " needs a value");
      val = argv[++i];
    }
    if (kBatchValueOptions.count(key)) {
      if (a.own.count(key) && key != "merge") throw InputError("option --" + key + " given twice");
      a.own[key].push_back(val);
    } else {
      a.forwarded.push_back("--" + key);
      a.forwarded.push_back(val);
    }
  }
  return a;
}

long positiveInt(const std::string& name, const std::string& s) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || v < 1 || v > 4096)
    throw InputError("option --" + name + " needs an integer from 1 to 4096, got '" + s + "'");
  return v;
}

void checkMode(const std::string& mode, const std::string& where) {
  static const std::set<std::string> modes = {"free_decay", "forced", "ringdown", "response"};
  if (!modes.count(mode))
    throw InputError(where + "mode '" + mode +
                     "' is not one of free_decay, forced, ringdown, response");
}

void makeFleetReport(const std::string& dir) {
  std::string script = executableDirectory() + "/fleet_report.py";
  if (!fs::is_regular_file(script)) script = findPackageResource("scripts/fleet_report.py");
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir + "'";
  if (std::system(cmd.c_str()) != 0)
    std::cerr << "cvg_ident batch: the fleet report was not made (" << cmd
              << " failed); the tables are in " << dir << "\n";
}

int merge(const BatchArgs& a, const std::string& out) {
  std::vector<std::string> dirs = a.own.at("merge");
  dirs.insert(dirs.end(), a.positionals.begin(), a.positionals.end());
  std::map<size_t, FleetEntry> by_index;
  size_t record_count = 0;
  fs::create_directories(fs::path(out) / "records");
  for (const auto& d : dirs) {
    if (!fs::is_directory(fs::path(d) / "records"))
      throw InputError("--merge " + d + ": no records/ folder (not a batch output folder)");
    for (auto& e : readFleetEntries(d)) {
      const size_t n = static_cast<size_t>(intField(e.status, "record_count", 0));
      if (record_count != 0 && n != record_count)
        throw InputError("--merge " + d + ": record " + stringField(e.status, "record") +
                         " is from a list of " + std::to_string(n) + " records, others from " +
                         std::to_string(record_count) + " (different batches)");
      record_count = n;
      const size_t i = static_cast<size_t>(intField(e.status, "index", 0));
      if (by_index.count(i)) continue;  // the same record in two folders: the first is kept
      if (!fs::equivalent(d, out)) {
        const fs::path src = fs::path(d) / "records", dst = fs::path(out) / "records";
        const std::string name = stringField(e.status, "record");
        for (const auto& f : {name + ".json", name + ".log", name + ".status.json"})
          if (fs::exists(src / f))
            fs::copy_file(src / f, dst / f, fs::copy_options::overwrite_existing);
        if (fs::is_directory(src / (name + "_report")))
          fs::copy(src / (name + "_report"), dst / (name + "_report"),
                   fs::copy_options::recursive | fs::copy_options::overwrite_existing);
      }
      by_index[i] = std::move(e);
    }
  }
  std::vector<FleetEntry> entries;
  for (auto& kv : by_index) entries.push_back(std::move(kv.second));
  std::vector<size_t> expected(record_count);
  for (size_t i = 0; i < record_count; ++i) expected[i] = i;
  writeFleetTable(entries, record_count, expected, out, "fleet", addPredictedDrift);
  const size_t missing = record_count - entries.size();
  std::cerr << "batch --merge: " << entries.size() << " of " << record_count << " records from "
            << dirs.size() << " folder(s) -> " << out << "/fleet.csv"
            << (missing ? " (" + std::to_string(missing) + " missing: see fleet.json)" : "")
            << "\n";
  if (!a.flags.count("no-plots")) makeFleetReport(out);
  return missing ? 1 : 0;
}

}  // namespace

int runBatch(const std::vector<std::string>& argv) {
  const BatchArgs a = parse(argv);
  if (a.flags.count("help")) {
    std::cout << kHelp;
    return 0;
  }
  const std::string out = a.get("out");
  if (out.empty()) throw InputError("batch needs --out DIR");
  if (a.own.count("merge")) return merge(a, out);
  if (a.positionals.empty()) throw InputError("batch needs INPUT files, patterns or a manifest");
  if (!a.own.count("mode"))
    throw InputError("batch needs --mode free_decay|forced|ringdown|response");
  const std::string mode = a.get("mode");
  checkMode(mode, "--mode: ");
  const bool explain = a.flags.count("explain") > 0;
  if (a.flags.count("reports") && !explain) throw InputError("--reports needs --explain");
  BatchRunOptions run;
  run.jobs = static_cast<int>(positiveInt("jobs", a.get("jobs", "1")));
  if (a.own.count("timeout")) {
    char* end = nullptr;
    const std::string t = a.get("timeout");
    run.timeout_s = std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0' || !(run.timeout_s > 0))
      throw InputError("option --timeout needs seconds > 0, got '" + t + "'");
  }
  std::string shard_source = "--shard";
  Shard shard;
  if (a.own.count("shard"))
    shard = parseShard(a.get("shard"));
  else
    shard = shardFromEnvironment(shard_source);

  const std::vector<BatchRecord> records = expandBatchInputs(a.positionals);
  const fs::path records_dir = fs::path(out) / "records";
  std::error_code ec;
  fs::create_directories(records_dir, ec);
  if (ec) throw InputError("--out " + out + ": cannot create " + records_dir.string());
  std::vector<BatchJob> jobs;
  for (const auto& r : records) {
    if (!shard.contains(r.index)) continue;
    BatchJob j;
    j.record = r;
    j.record_count = records.size();
    const std::string m = r.column("mode").empty() ? mode : r.column("mode");
    checkMode(m, r.input + ": manifest column 'mode': ");
    j.args = {explain ? "explain" : "identify", r.input, "--mode", m};
    j.args.insert(j.args.end(), a.forwarded.begin(), a.forwarded.end());
    bool has_frequency = false;
    for (const auto& f : a.forwarded) has_frequency |= f == "--frequency";
    if (m == "ringdown" && !has_frequency && !r.column("frequency_hz").empty()) {
      j.args.push_back("--frequency");
      j.args.push_back(r.column("frequency_hz"));
    }
    if (a.flags.count("reports")) {
      j.args.push_back("--report");
      j.args.push_back((records_dir / (r.name + "_report")).string());
    }
    j.json_path = (records_dir / (r.name + ".json")).string();
    j.log_path = (records_dir / (r.name + ".log")).string();
    j.status_path = (records_dir / (r.name + ".status.json")).string();
    j.input_hash = hashFile(r.input);
    std::string settings = "cvg_ident 0.1.0";  // package.xml version
    for (size_t k = 0; k < j.args.size(); ++k)
      if (k != 1) settings += '\0' + j.args[k];
    j.settings_hash = hashString(settings);
    jobs.push_back(std::move(j));
  }
  if (shard.count > 1)
    std::cerr << "batch: shard " << shard.index << "/" << shard.count << " (from " << shard_source
              << "): " << jobs.size() << " of " << records.size() << " records\n";
  const BatchRunSummary sum = runBatchJobs(jobs, run, a.flags.count("force") > 0);

  std::vector<FleetEntry> entries;
  for (const auto& e : readFleetEntries(out))
    for (const auto& j : jobs)
      if (stringField(e.status, "record") == j.record.name &&
          intField(e.status, "index", -1) == static_cast<long long>(j.record.index) &&
          stringField(e.status, "settings_hash") == j.settings_hash) {
        entries.push_back(e);
        break;
      }
  const std::string stem = shard.count > 1 ? "fleet_shard_" + std::to_string(shard.index) + "_of_" +
                                                 std::to_string(shard.count)
                                           : "fleet";
  std::vector<size_t> expected;
  for (const auto& j : jobs) expected.push_back(j.record.index);
  writeFleetTable(entries, records.size(), expected, out, stem, addPredictedDrift);
  size_t failed = 0;
  for (const auto& e : entries) failed += intField(e.status, "exit_status", 1) != 0;
  std::cerr << "batch: " << entries.size() << " records in " << out << "/" << stem << ".csv ("
            << failed << " failed: their exit status and message are in the table); ran " << sum.ran
            << ", skipped " << sum.skipped << "\n";
  if (shard.count == 1 && !a.flags.count("no-plots")) makeFleetReport(out);
  return sum.crashed > 0 || entries.size() < jobs.size() ? 1 : 0;
}

}  // namespace tools
}  // namespace cvg_bench
