#include "batch_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

#include "cvg_bench/core/common/errors.h"
#include "json_fields.h"

namespace cvg_bench {
namespace tools {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

std::string selfExecutable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("batch: cannot find the cvg_ident executable (/proc/self/exe)");
  return p.string();
}

/// The error line a failed cvg_ident run printed last ("... error: ...", "analysis failed: ..."),
/// else its last non-empty line.
std::string failureMessage(const std::string& log_path) {
  std::ifstream in(log_path);
  std::string line, last, last_error;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    last = line;
    if (line.find("error:") != std::string::npos ||
        line.find("analysis failed:") != std::string::npos)
      last_error = line;
  }
  std::string m = last_error.empty() ? last : last_error;
  if (m.size() > 400) m = m.substr(0, 400) + "...";
  return m;
}

void writeAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    if (!out) throw InputError(path + ": cannot write");
  }
  fs::rename(tmp, path);
}

struct Running {
  size_t job = 0;
  Clock::time_point start;
  bool timed_out = false;
};

pid_t startJob(const BatchJob& job, const std::string& exe) {
  std::error_code ec;
  fs::remove(job.json_path, ec);
  fs::remove(job.json_path + ".part", ec);
  fs::remove(job.status_path, ec);
  std::vector<std::string> args = job.args;
  args.push_back("--json");
  args.push_back(job.json_path + ".part");
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw AnalysisError(std::string("batch: fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    // The child dies with the batch (a killed batch leaves no orphan writing into DIR).
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(137);
    const int log = open(job.log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = open("/dev/null", O_RDONLY);
    if (log >= 0) {
      dup2(log, 1);
      dup2(log, 2);
    }
    if (null >= 0) dup2(null, 0);
    execv(exe.c_str(), argv.data());
    std::fprintf(stderr, "cvg_ident batch: error: cannot run %s: %s\n", exe.c_str(),
                 std::strerror(errno));
    _exit(127);
  }
  return pid;
}

void finishJob(const BatchJob& job, int wait_status, const rusage& ru, double seconds,
               bool timed_out, double timeout_s) {
  int exit_status = 0;
  std::string message;
  if (timed_out) {
    exit_status = 128 + SIGKILL;
    message = "timed out after " + std::to_string(timeout_s) + " s (--timeout)";
  } else if (WIFSIGNALED(wait_status)) {
    exit_status = 128 + WTERMSIG(wait_status);
    message = std::string("killed by signal ") + std::to_string(WTERMSIG(wait_status)) + " (" +
              strsignal(WTERMSIG(wait_status)) + ")";
  } else {
    exit_status = WEXITSTATUS(wait_status);
    if (exit_status != 0) message = failureMessage(job.log_path);
  }
  std::error_code ec;
  const bool has_json = exit_status == 0 && fs::is_regular_file(job.json_path + ".part");
  if (has_json)
    fs::rename(job.json_path + ".part", job.json_path);
  else
    fs::remove(job.json_path + ".part", ec);
  if (exit_status == 0 && !has_json) {
    exit_status = 1;
    message = "exit 0 but no JSON written";
  }
  nlohmann::ordered_json columns = nlohmann::ordered_json::object();
  for (const auto& kv : job.record.columns) columns[kv.first] = kv.second;
  nlohmann::ordered_json s;
  s["record"] = job.record.name;
  s["input"] = job.record.input;
  s["index"] = job.record.index;
  s["record_count"] = job.record_count;
  s["columns"] = columns;
  s["args"] = job.args;
  s["input_hash"] = job.input_hash;
  s["settings_hash"] = job.settings_hash;
  s["exit_status"] = exit_status;
  s["message"] = message;
  s["json"] = has_json ? fs::path(job.json_path).filename().string() : "";
  s["log"] = fs::path(job.log_path).filename().string();
  s["seconds"] = seconds;
  s["peak_rss_kb"] = ru.ru_maxrss;
  s["complete"] = true;
  writeAtomically(job.status_path, s.dump(1) + "\n");
}

std::string duration(double s) {
  char buf[32];
  if (s < 90)
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  else if (s < 5400)
    std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else
    std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  return buf;
}

}  // namespace

nlohmann::json readBatchStatus(const std::string& path) {
  std::ifstream in(path);
  if (!in) return nlohmann::json::object();
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  // Only a complete status of the expected shape counts; anything else (truncated, hand-edited,
  // another version) is as if absent: the record runs again, a merge leaves it out.
  const std::string name = stringField(j, "record");
  const long long index = intField(j, "index", -1), count = intField(j, "record_count", -1);
  const bool ok = !j.is_discarded() && boolField(j, "complete", false) && !name.empty() &&
                  name.find('/') == std::string::npos && name[0] != '.' && index >= 0 &&
                  count > index && intField(j, "exit_status", -1) >= 0 &&
                  j.contains("input_hash") && j["input_hash"].is_string() &&
                  j.contains("settings_hash") && j["settings_hash"].is_string() &&
                  j.contains("json") && j["json"].is_string() &&
                  (stringField(j, "json").empty() || stringField(j, "json") == name + ".json");
  return ok ? j : nlohmann::json::object();
}

bool batchJobDone(const BatchJob& job) {
  const nlohmann::json s = readBatchStatus(job.status_path);
  if (s.empty() || stringField(s, "input_hash") != job.input_hash ||
      stringField(s, "settings_hash") != job.settings_hash)
    return false;
  const long long rc = intField(s, "exit_status", -1);
  if (rc == 1 || rc == 2) return true;
  if (rc != 0) return false;
  std::ifstream in(job.json_path);
  return in && !nlohmann::json::parse(in, nullptr, false).is_discarded();
}

BatchRunSummary runBatchJobs(const std::vector<BatchJob>& jobs, const BatchRunOptions& options,
                             bool force) {
  BatchRunSummary sum;
  std::deque<size_t> todo;
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (!force && batchJobDone(jobs[i]))
      ++sum.skipped;
    else
      todo.push_back(i);
  }
  const std::string exe = selfExecutable();
  const size_t total = todo.size();
  const bool tty = isatty(2);
  std::cerr << "batch: " << jobs.size() << " records, " << sum.skipped
            << " already done with the same input and settings, " << total << " to run on "
            << options.jobs << " job" << (options.jobs > 1 ? "s" : "") << "\n";
  const auto t0 = Clock::now();
  auto last_print = t0;
  std::map<pid_t, Running> running;
  while (!todo.empty() || !running.empty()) {
    while (!todo.empty() && static_cast<int>(running.size()) < options.jobs) {
      const size_t j = todo.front();
      todo.pop_front();
      running[startJob(jobs[j], exe)] = Running{j, Clock::now(), false};
    }
    int st = 0;
    rusage ru{};
    // Without a timeout the batch sleeps in wait4 until a record ends; with one it polls (2 ms).
    const pid_t pid = wait4(-1, &st, options.timeout_s > 0 ? WNOHANG : 0, &ru);
    if (pid <= 0) {
      if (options.timeout_s > 0)
        for (auto& r : running)
          if (!r.second.timed_out &&
              std::chrono::duration<double>(Clock::now() - r.second.start).count() >
                  options.timeout_s) {
            kill(r.first, SIGKILL);
            r.second.timed_out = true;
          }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      continue;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const BatchJob& job = jobs[it->second.job];
    const double secs = std::chrono::duration<double>(Clock::now() - it->second.start).count();
    finishJob(job, st, ru, secs, it->second.timed_out, options.timeout_s);
    const long long rc = intField(readBatchStatus(job.status_path), "exit_status", 1);
    ++sum.ran;
    if (rc == 1 || rc == 2) ++sum.failed;
    if (rc > 2) ++sum.crashed;
    running.erase(it);
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - t0).count();
    if (tty || sum.ran == total || now - last_print > std::chrono::seconds(5)) {
      last_print = now;
      const double rate = sum.ran / std::max(elapsed, 1e-9);
      std::ostringstream line;
      line << "batch: " << sum.ran << "/" << total << " done (" << sum.failed << " failed";
      if (sum.crashed) line << ", " << sum.crashed << " crashed or timed out";
      line << "), " << std::fixed;
      line.precision(1);
      line << rate * 60 << " records/min, ";
      line << (sum.ran == total ? "took " + duration(elapsed)
                                : duration((total - sum.ran) / rate) + " left");
      std::cerr << (tty ? "\r" : "") << line.str() << (tty ? "\033[K" : "\n")
                << (tty && sum.ran == total ? "\n" : "") << std::flush;
    }
  }
  sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return sum;
}

}  // namespace tools
}  // namespace cvg_bench
