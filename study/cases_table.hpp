// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// cases.csv (docs/reference/studies.md, "Collecting"): one row a case — its index, the varied fields'
// values, status, energy, max violation, iterations, time and host.

#include <vector>

#include "study/study_folder.hpp"

namespace mcopt::study {

/// Writes the study's cases.csv atomically and returns the cases' reports, in order.
std::vector<CaseReport> writeCasesCsv(const StudyFolder& folder, const StudyDescription& study);

}  // namespace mcopt::study
