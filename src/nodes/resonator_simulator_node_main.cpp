// Simulated resonator on the bench (see include/cvg_bench/ros/simulator_node.h).
#include "cvg_bench/ros/node_runner.h"
#include "cvg_bench/ros/simulator_node.h"

int main(int argc, char** argv) {
  return cvg_bench::runNode<cvg_bench::SimulatorNode>(argc, argv, "resonator_simulator");
}
