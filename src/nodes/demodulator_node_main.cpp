// Raw f, g -> slow variables (see include/cvg_bench/ros/demodulator_node.h).
#include "cvg_bench/ros/demodulator_node.h"
#include "cvg_bench/ros/node_runner.h"

int main(int argc, char** argv) {
  return cvg_bench::runNode<cvg_bench::DemodulatorNode>(argc, argv, "demodulator");
}
