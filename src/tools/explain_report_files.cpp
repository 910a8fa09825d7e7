#include "explain_report_files.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "cvg_bench/core/common/errors.h"
#include "cvg_bench/core/common/package_resources.h"
#include "cvg_bench/core/estimate/output_error_free_decay.h"
#include "cvg_bench/core/model/orbit_elements.h"
#include "cvg_bench/core/model/stationary_solver.h"
#include "cvg_bench/report/estimate_json.h"

namespace cvg_bench {
namespace tools {

using report::writeJsonFile;
namespace {

void makeDirectory(const std::string& dir) {
  std::string partial;
  for (size_t i = 0; i <= dir.size(); ++i) {
    if (i == dir.size() || dir[i] == '/') {
      if (!partial.empty()) ::mkdir(partial.c_str(), 0755);
    }
    if (i < dir.size()) partial += dir[i];
  }
  struct stat st;
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw InputError("--report: cannot create directory '" + dir + "'");
}

std::ofstream openOut(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw InputError("--report: cannot write '" + path + "'");
  out << std::setprecision(10);
  return out;
}

void writeCurveRow(std::ofstream& out, const std::string& model, double x,
                   const Eigen::Vector4d& q) {
  const OrbitElements e = orbitFromSlow(q);
  out << model << "," << x << "," << q[0] << "," << q[1] << "," << q[2] << "," << q[3] << ","
      << std::hypot(q[0], q[1]) << "," << std::hypot(q[2], q[3]) << "," << std::atan2(q[1], q[0])
      << "," << std::atan2(q[3], q[2]) << "," << e.r << "," << e.k << "," << e.theta << "\n";
}

/// The models of the ladder: baseline, each accepted step, the final model (no repeats).
std::vector<const NestedFit*> ladder(const Explanation& x) {
  std::vector<const NestedFit*> out = {&x.selection.baseline};
  for (const auto& s : x.selection.steps) out.push_back(&s.fit);
  bool has_final = false;
  for (const auto* f : out) has_final |= f->model == x.selection.final_fit.model;
  if (!has_final) out.push_back(&x.selection.final_fit);
  return out;
}

/// The model of a fit (with mu as an extension when estimated) and its z; mu in *mu.
ResonatorModel modelOf(const NestedFit& f, ExperimentMode mode, Eigen::VectorXd* z, double* mu) {
  const ResonatorModel model(f.model, mode);
  ParameterValues values;
  for (size_t i = 0; i < f.estimate.names.size(); ++i)
    values[f.estimate.names[i]] = f.estimate.values[i];
  *mu = values.count("mu") ? values.at("mu") : 0.0;
  *z = model.parameterVector(values);
  return model;
}

}  // namespace

void writeExplainReportFiles(const std::string& dir, const nlohmann::json& explanation_json,
                             const Explanation& x, const SlowRecord* slow, const SweepRecord* sweep,
                             int rk4_substeps) {
  makeDirectory(dir);
  writeJsonFile(explanation_json, dir + "/explain.json");

  std::ofstream curves = openOut(dir + "/curves.csv");
  curves << "model,x,q1,p1,q2,p2,A,B,phase_a,phase_b,r,k,theta\n";
  if (slow) {
    for (size_t i = 0; i < slow->size(); ++i)
      writeCurveRow(curves, "measured", slow->t_s[i] - slow->t_s.front(), slow->q[i]);
    std::vector<double> t(slow->t_s);
    for (const NestedFit* f : ladder(x)) {
      Eigen::VectorXd z;
      double mu = 0.0;
      const ResonatorModel model = modelOf(*f, ExperimentMode::kFreeDecay, &z, &mu);
      std::vector<Eigen::Vector4d> traj;
      integrateSlowTrajectory(model, z, slow->q.front(), t, rk4_substeps, &traj);
      for (size_t i = 0; i < traj.size(); ++i)
        writeCurveRow(curves, f->model, t[i] - t.front(), traj[i]);
    }
  }
  if (sweep) {
    const double omega =
        x.finalEstimate().omega_rad_s > 0 ? x.finalEstimate().omega_rad_s : sweep->omega_rad_s;
    for (size_t j = 0; j < sweep->size(); ++j)
      writeCurveRow(curves, "measured", sweep->omega0_rad_s[j], sweep->q[j]);
    for (const NestedFit* f : ladder(x)) {
      Eigen::VectorXd z;
      double mu = 0.0;
      const ResonatorModel model = modelOf(*f, ExperimentMode::kForced, &z, &mu);
      SlowContext ctx;
      ctx.mu = mu;
      // Model stationary points on the branch of each measured point (Newton from it).
      for (size_t j = 0; j < sweep->size(); ++j) {
        const StationaryPoint sp = solveStationaryPoint(
            model, z, ctx, detuningRate(omega, sweep->omega0_rad_s[j]), sweep->q[j]);
        if (sp.converged) writeCurveRow(curves, f->model, sweep->omega0_rad_s[j], sp.q);
      }
    }
  }

  std::ofstream res = openOut(dir + "/residuals.csv");
  res << "model,x,radial,tangential,amp2,theta\n";
  const std::pair<const std::vector<BlockResidual>*, std::string> sets[] = {
      {&x.baseline_blocks, x.selection.baseline.model},
      {&x.final_blocks, x.selection.final_fit.model}};
  for (const auto& s : sets) {
    if (s.second == x.selection.baseline.model && s.first == &x.final_blocks) continue;
    for (const auto& b : *s.first)
      res << s.second << "," << b.abscissa << "," << b.radial << "," << b.tangential << ","
          << b.amp2 << "," << b.theta << "\n";
  }

  std::ofstream sig = openOut(dir + "/signature.csv");
  sig << "model,variable,component,bin_center,mean,sem\n";
  const std::pair<const ResidualSignature*, std::string> sigs[] = {
      {&x.baseline_signature, x.selection.baseline.model},
      {&x.final_signature, x.selection.final_fit.model}};
  for (const auto& s : sigs) {
    if (s.second == x.selection.baseline.model && s.first == &x.final_signature) continue;
    for (const auto& e : s.first->entries)
      for (const auto& b : e.bins)
        sig << s.second << "," << e.variable << "," << e.component << "," << b.center << ","
            << b.mean << "," << b.sem << "\n";
  }
}

bool runExplainReportScript(const std::string& dir) {
  // Installed next to cvg_ident (catkin_install_python), else in the package's scripts/.
  std::string script = executableDirectory() + "/explain_report.py";
  if (!std::filesystem::is_regular_file(script))
    script = findPackageResource("scripts/explain_report.py");
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir + "'";
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    std::cerr << "cvg_ident explain: the figures were not made (" << cmd << " exited with " << rc
              << "); the data files are in " << dir << "\n";
    return false;
  }
  return true;
}

}  // namespace tools
}  // namespace cvg_bench
