// Several free decays of one resonator as one record for one fit (docs/interfaces.md, identify).
#pragma once

#include <string>
#include <vector>

#include "cvg_bench/core/io/records.h"

namespace cvg_bench {

/// Joins free decays of one resonator (e.g. started at several pattern angles, which separates the
/// damping and frequency anisotropies' two axes better than one decay does) into one SlowRecord:
/// each record keeps its samples and is shifted in time to start `gap_steps` median sample steps
/// after the previous one ends, so the time-gap rule of the free-decay regression
/// (free_decay_regression.h: a step over 5x the median) leaves the equations across every join
/// out. The natural frequencies must agree (relative 1e-9) or be unknown in all; extra columns are
/// kept only when every record has them. `notes` gets one sentence saying what was joined.
/// InputError (naming the record) on an empty list, an empty record, differing frequencies or one
/// source given twice.
SlowRecord stackFreeDecays(const std::vector<SlowRecord>& records, std::vector<std::string>& notes,
                           double gap_steps = 20.0);

}  // namespace cvg_bench
