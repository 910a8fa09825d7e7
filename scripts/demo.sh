#!/usr/bin/env bash
# make demo: the main job on the built-in default.
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== cvg_bench demo: the paper's section-4 MEMS ring estimate =="
bin/cvg_ident drift --params config/paper_section4_estimate.json --r 1.0 --k 0.05 --theta-grid 8
