#!/usr/bin/env bash
# `make validate`: the independent validation harness (scripts/validate_independent.py: explain
# verdicts and identify intervals on records the fit does not share), then, where present, the
# ring-down validation. Extra arguments go to the harness (e.g. --quick, --kinds fd_slow,sweep,
# --compare build/validate/before.json). Clean trajectories are cached in build/validate/work; the
# run's results are kept in build/validate/last.json (the input of a later --compare).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mkdir -p build/validate/work
/usr/bin/python3 scripts/validate_independent.py --jobs "${VALIDATE_JOBS:-2}" \
  --markdown docs/validation_independent.md --explain-doc docs/validation_explain.md \
  --coverage-doc docs/validation.md --work build/validate/work --json build/validate/last.json "$@"
if [ -f scripts/validate_ringdown.py ]; then
  /usr/bin/python3 scripts/validate_ringdown.py --n 60 --markdown docs/validation_ringdown.md
fi
