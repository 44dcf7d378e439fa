// SPDX-License-Identifier: BSD-3-Clause
#include "study/cases_table.hpp"

#include <cstdio>

#include "core/atomic_file.hpp"

namespace mcopt::study {

namespace {

/// RFC 4180: a field with a comma, a quote or a line break is quoted, quotes doubled.
std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string number(const std::optional<double>& value) {
  if (!value) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", *value);
  return text;
}

}  // namespace

std::vector<CaseReport> writeCasesCsv(const StudyFolder& folder, const StudyDescription& study) {
  std::string csv = "case";
  for (const std::string& field : study.fields) csv += "," + csvField(field);
  csv += ",status,energy,max_violation,iterations,seconds,host\n";
  std::vector<CaseReport> reports;
  for (std::size_t k = 0; k < study.caseCount(); ++k) {
    const CaseReport r = caseReport(folder, k);
    csv += std::to_string(k);
    for (const std::string& value : study.values[k]) csv += "," + csvField(value);
    csv += "," + csvField(r.status) + "," + number(r.energy) + "," + number(r.maxViolation) + "," +
           (r.iterations ? std::to_string(*r.iterations) : "") + "," + number(r.seconds) + "," + csvField(r.host) + "\n";
    reports.push_back(r);
  }
  writeFileAtomically(folder.casesCsv(), csv);
  return reports;
}

}  // namespace mcopt::study
