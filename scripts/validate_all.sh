#!/usr/bin/env bash
# `make validate`: the independent validation harness (scripts/validate_independent.py: explain
# verdicts and identify intervals on records the fit does not share), then, where present, the
# ring-down validation, the real ring-downs and the one-mode response harness (30 records a class,
# ~22 min on 2 cores: the whole of `make validate` now takes about an hour). Extra arguments go
# to the harness (e.g. --quick, --kinds fd_slow,sweep,
# --compare build/validate/before.json). Clean trajectories are cached in build/validate/work; the
# run's results are kept in build/validate/last.json (the input of a later --compare).
# --thin 3 (every clean record, a seed-chosen third of the others: 590 runs, ~10 min) keeps the
# whole of `make validate` under 30 minutes on 2 cores with the ring-down part (~11 min at 60
# records a class); the docs' tables are made this way. THIN=1 runs every case.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
mkdir -p build/validate/work
/usr/bin/python3 scripts/validate_independent.py --jobs "${VALIDATE_JOBS:-2}" --thin "${THIN:-3}" \
  --markdown docs/validation_independent.md --explain-doc docs/validation_explain.md \
  --coverage-doc docs/validation.md --work build/validate/work --json build/validate/last.json "$@"
if [ -f scripts/validate_ringdown.py ]; then
  /usr/bin/python3 scripts/validate_ringdown.py --n 100 --markdown docs/validation_ringdown.md
fi
if [ -f scripts/validation/validate_real_ringdown.py ]; then
  /usr/bin/python3 scripts/validation/validate_real_ringdown.py --part all --jobs "${VALIDATE_JOBS:-2}" \
    --out build/validate_real --markdown docs/validation_ringdown_real_tables.md
fi
if [ -f scripts/validation/validate_response.py ]; then
  /usr/bin/python3 scripts/validation/validate_response.py --n 30 --jobs "${VALIDATE_JOBS:-2}" \
    --markdown docs/validation_response_tables.md
fi
if [ -f scripts/validation/validate_drift.py ]; then
  /usr/bin/python3 scripts/validation/validate_drift.py --out build/validate_drift
  # Held at quadrature k0 = 0.2 r0, where the cubic terms and xi_diff move theta' (every case
  # pooled over 10 seeds, decays started at +-k0; docs/validation_drift.md; ~20 min on 2 cores).
  /usr/bin/python3 scripts/validation/validate_drift.py --k0 0.2 --pool-only --pool-cases all \
    --pool 10 --jobs "${VALIDATE_JOBS:-2}" --out build/validate_drift_k0
fi
