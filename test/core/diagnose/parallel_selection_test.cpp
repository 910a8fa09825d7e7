// The selection's candidate fits and hold-outs run several at a time (parallel_tasks.h,
// SelectionOptions::threads): the selection, every criterion, estimate and note must be the same
// as with one thread, bit for bit.
#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "cvg_bench/core/diagnose/explanation.h"
#include "cvg_bench/core/diagnose/parallel_tasks.h"
#include "cvg_bench/core/model/resonator_preset.h"
#include "cvg_bench/core/simulate/experiment_runner.h"

namespace cvg_bench {
namespace {

TEST(ParallelTasks, EveryTaskRunsOnceForAnyThreadCount) {
  for (int threads : {0, 1, 2, 5}) {
    std::vector<std::atomic<int>> runs(37);
    for (auto& r : runs) r = 0;
    runTasks(runs.size(), threads, [&](size_t i) { ++runs[i]; });
    for (size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i], 1) << "task " << i;
  }
  EXPECT_EQ(taskThreads(3, 2), 2);
  EXPECT_EQ(taskThreads(3, 0), 1);
  EXPECT_GE(taskThreads(0, 8), 1);
}

void expectSameEstimate(const Estimate& a, const Estimate& b, const std::string& what) {
  ASSERT_EQ(a.names, b.names) << what;
  for (size_t i = 0; i < a.names.size(); ++i) {
    EXPECT_EQ(a.values[i], b.values[i]) << what << " " << a.names[i];
    EXPECT_EQ(a.parameters.at(a.names[i]).std_error, b.parameters.at(b.names[i]).std_error)
        << what << " " << a.names[i];
  }
  EXPECT_EQ(a.sigma, b.sigma) << what;
}

// Cubic and quintic stiffness hidden in a mems_ring decay: two terms chosen, so the finalists, the
// neighbour round, the backward check, the hold-outs and a two-step ladder all run in batches.
TEST(ParallelSelection, ThreadsGiveTheSameSelectionAndNumbers) {
  ResonatorPreset p = loadShippedPreset("mems_ring");
  p.applyEffect("xi", 30.0);
  p.applyEffect("kappa", 30.0);
  SimulationOptions sim;
  sim.seed = 101;
  const SlowRecord rec = simulateExperiment(p, sim).slow;
  ExplainOptions serial, parallel;
  serial.selection.threads = 1;
  parallel.selection.threads = 3;  // more threads than this machine's cores is allowed
  const Explanation a = explainFreeDecay(rec, serial);
  const Explanation b = explainFreeDecay(rec, parallel);
  const SelectionResult &sa = a.selection, &sb = b.selection;
  ASSERT_EQ(sa.selected.size(), 2u) << a.cause;
  EXPECT_EQ(sa.selected, sb.selected);
  EXPECT_EQ(sa.dropped, sb.dropped);
  EXPECT_EQ(a.cause, b.cause);
  EXPECT_EQ(a.notes, b.notes);
  EXPECT_EQ(a.unexplained, b.unexplained);
  EXPECT_EQ(sa.correlation_factor, sb.correlation_factor);
  EXPECT_EQ(sa.runner_up.model, sb.runner_up.model);
  EXPECT_EQ(sa.runner_up_delta, sb.runner_up_delta);
  ASSERT_EQ(sa.subsets.size(), sb.subsets.size());
  int refined = 0, with_holdout = 0;
  for (size_t i = 0; i < sa.subsets.size(); ++i) {
    const SubsetScore &x = sa.subsets[i], &y = sb.subsets[i];
    EXPECT_EQ(x.model, y.model);
    EXPECT_EQ(x.refined, y.refined) << x.model;
    EXPECT_EQ(x.criterion, y.criterion) << x.model;
    EXPECT_EQ(x.sigma, y.sigma) << x.model;
    EXPECT_EQ(x.holdout_ratio, y.holdout_ratio) << x.model;
    refined += x.refined;
    with_holdout += x.holdout_ratio > 0.0;
  }
  EXPECT_GE(refined, 5);  // the linear model and 4 finalists at least
  EXPECT_GE(with_holdout, 2);
  ASSERT_EQ(sa.steps.size(), sb.steps.size());
  for (size_t i = 0; i < sa.steps.size(); ++i) {
    EXPECT_EQ(sa.steps[i].added, sb.steps[i].added);
    EXPECT_EQ(sa.steps[i].holdout_ratio, sb.steps[i].holdout_ratio);
    EXPECT_EQ(sa.steps[i].wald.f_statistic, sb.steps[i].wald.f_statistic);
    expectSameEstimate(sa.steps[i].fit.estimate, sb.steps[i].fit.estimate, sa.steps[i].model);
  }
  expectSameEstimate(a.finalEstimate(), b.finalEstimate(), "final");
}

}  // namespace
}  // namespace cvg_bench
