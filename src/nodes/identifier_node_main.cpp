// Parameter identification on the bench (see include/cvg_bench/ros/identifier_node.h).
#include "cvg_bench/ros/identifier_node.h"
#include "cvg_bench/ros/node_runner.h"

int main(int argc, char** argv) {
  return cvg_bench::runNode<cvg_bench::IdentifierNode>(argc, argv, "identifier");
}
