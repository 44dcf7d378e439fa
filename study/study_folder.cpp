// SPDX-License-Identifier: BSD-3-Clause
#include "study/study_folder.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/errors.hpp"

namespace mcopt::study {

namespace {

using Json = nlohmann::json;

std::optional<Json> readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  try {
    return Json::parse(in);
  } catch (const Json::exception&) {
    return std::nullopt;  // files are written atomically: a partial one is not ours
  }
}

std::string fileText(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Json studyJson(const Sweep& sweep, const std::vector<StudyCase>& cases) {
  Json study;
  study["sweep"] = std::filesystem::absolute(sweep.file).lexically_normal().string();
  study["base_scenario"] = sweep.baseScenario.string();
  study["design"] = toString(sweep.design);
  if (sweep.design != Design::Grid) study["seed"] = sweep.seed;
  Json fields = Json::array();
  for (const VariedField& f : sweep.varied) fields.push_back(f.path.text);
  study["fields"] = fields;
  study["resources"] = {{"threads", sweep.resources.threads},
                        {"time_seconds", sweep.resources.timeLimitSeconds},
                        {"memory", sweep.resources.memory}};
  Json list = Json::array();
  for (const StudyCase& c : cases) {
    Json values = Json::array();
    for (const YAML::Node& v : c.values) values.push_back(valueText(v));
    list.push_back({{"index", c.index}, {"values", values}});
  }
  study["cases"] = list;
  return study;
}

/// Statuses a restart does not run again (docs/reference/results.md, "Results"): the solver ended.
bool finalStatus(const std::string& status) { return !status.empty() && status != "running" && status != "interrupted"; }

}  // namespace

StudyFolder::StudyFolder(std::filesystem::path root) : root_(std::move(root)) {}

std::filesystem::path StudyFolder::caseFolder(std::size_t k) const {
  char name[32];
  std::snprintf(name, sizeof name, "%04zu", k);
  return root_ / "cases" / name;
}

const char* toString(CaseState state) {
  switch (state) {
    case CaseState::Pending: return "pending";
    case CaseState::Running: return "running";
    case CaseState::Finished: return "finished";
    case CaseState::Failed: return "failed";
    case CaseState::TimedOut: return "timeout";
    case CaseState::Cancelled: return "cancelled";
    case CaseState::Crashed: return "crashed";
  }
  return "?";
}

void prepareStudy(const StudyFolder& folder, const Sweep& sweep, const std::vector<StudyCase>& cases) {
  const Json study = studyJson(sweep, cases);
  if (std::filesystem::exists(folder.studyFile())) {
    const std::optional<Json> old = readJson(folder.studyFile());
    if (!old) throw InputError(folder.studyFile().string() + ": not a study's description: choose another --out");
    // The sweep file may have moved; what must not change is what runs.
    for (const char* key : {"base_scenario", "design", "fields", "cases", "resources"})
      if (!old->contains(key) || (*old)[key] != study[key])
        throw InputError(folder.root().string() + " holds another study (its study.json differs in '" + key +
                         "'): choose another --out, or remove it");
    for (const StudyCase& c : cases)
      if (std::filesystem::exists(folder.scenarioFile(c.index)) &&
          fileText(folder.scenarioFile(c.index)) != caseScenarioText(sweep, c))
        throw InputError(folder.scenarioFile(c.index).string() + " differs from the sweep's case " + std::to_string(c.index) +
                         ": choose another --out, or remove it");
  }
  std::error_code error;
  std::filesystem::create_directories(folder.root() / "cases", error);
  if (error) throw InputError(folder.root().string() + ": cannot create the study folder (" + error.message() + ")");
  for (const StudyCase& c : cases) {
    std::filesystem::create_directories(folder.caseFolder(c.index), error);
    if (error) throw InputError(folder.caseFolder(c.index).string() + ": cannot create (" + error.message() + ")");
    writeFileAtomically(folder.scenarioFile(c.index), caseScenarioText(sweep, c));
  }
  writeFileAtomically(folder.studyFile(), study.dump(2) + "\n");
}

StudyDescription readStudy(const StudyFolder& folder) {
  const std::optional<Json> study = readJson(folder.studyFile());
  if (!study) throw InputError(folder.studyFile().string() + ": no study here (study.json missing or unreadable)");
  try {
    StudyDescription d;
    d.sweepFile = study->at("sweep").get<std::string>();
    d.baseScenario = study->at("base_scenario").get<std::string>();
    d.design = study->at("design").get<std::string>();
    d.fields = study->at("fields").get<std::vector<std::string>>();
    for (const Json& c : study->at("cases")) d.values.push_back(c.at("values").get<std::vector<std::string>>());
    const Json& r = study->at("resources");
    d.resources.threads = r.at("threads").get<int>();
    d.resources.timeLimitSeconds = r.at("time_seconds").get<double>();
    d.resources.memory = r.at("memory").get<std::string>();
    return d;
  } catch (const Json::exception& e) {
    throw InputError(folder.studyFile().string() + ": not a study's description (" + e.what() + ")");
  }
}

std::optional<CaseRecord> readCaseRecord(const StudyFolder& folder, std::size_t k) {
  const std::optional<Json> j = readJson(folder.recordFile(k));
  if (!j) return std::nullopt;
  CaseRecord r;
  r.host = j->value("host", "");
  r.end = j->value("end", "");
  r.slurmJob = j->value("slurm_job", "");
  r.attempts = j->value("attempts", 0);
  r.exitCode = j->value("exit_code", -1);
  r.signal = j->value("signal", 0);
  r.pid = j->value("pid", 0L);
  r.seconds = j->value("seconds", 0.0);
  return r;
}

void writeCaseRecord(const StudyFolder& folder, std::size_t k, const CaseRecord& r) {
  Json j = {{"host", r.host}, {"attempts", r.attempts}, {"pid", r.pid}, {"state", r.end.empty() ? "running" : "ended"}};
  if (!r.slurmJob.empty()) j["slurm_job"] = r.slurmJob;
  if (!r.end.empty()) {
    j["end"] = r.end;
    j["exit_code"] = r.exitCode;
    j["signal"] = r.signal;
    j["seconds"] = r.seconds;
  }
  writeFileAtomically(folder.recordFile(k), j.dump(2) + "\n");
}

CaseReport caseReport(const StudyFolder& folder, std::size_t k) {
  CaseReport report;
  const std::optional<CaseRecord> record = readCaseRecord(folder, k);
  if (record) {
    report.host = record->host;
    report.attempts = record->attempts;
  }
  const std::optional<Json> result = readJson(folder.resultFolder(k) / "result.json");
  if (result) {
    const auto number = [&](const Json& j) -> std::optional<double> {
      return j.is_number() ? std::optional<double>(j.get<double>()) : std::nullopt;
    };
    report.energy = number(result->value("energy", Json()));
    report.maxViolation = number(result->value("max_violation", Json()));
    if (result->contains("timings")) report.seconds = number((*result)["timings"].value("total_seconds", Json()));
    if (result->contains("solver")) {
      const Json& solver = (*result)["solver"];
      const Json its = solver.value("iterations_all_stages", solver.value("iterations", Json()));
      if (its.is_number_integer()) report.iterations = its.get<int>();
    }
  }
  const std::string status = result ? result->value("status", "") : "";
  if (finalStatus(status)) {
    report.state = CaseState::Finished;
    report.status = status;
    return report;
  }
  if (!record) report.state = CaseState::Pending;
  else if (record->end.empty()) report.state = CaseState::Running;
  else if (record->end == "timeout") report.state = CaseState::TimedOut;
  else if (record->end == "cancelled") report.state = CaseState::Cancelled;
  else if (record->end == "crashed") report.state = CaseState::Crashed;
  else report.state = CaseState::Failed;
  report.status = toString(report.state);
  return report;
}

std::vector<std::size_t> unfinishedCases(const StudyFolder& folder, const StudyDescription& study) {
  std::vector<std::size_t> cases;
  for (std::size_t k = 0; k < study.caseCount(); ++k)
    if (caseReport(folder, k).state != CaseState::Finished) cases.push_back(k);
  return cases;
}

}  // namespace mcopt::study
