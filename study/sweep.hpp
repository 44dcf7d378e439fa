// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A sweep (docs/reference/studies.md): a base scenario, fields set for every case, and fields varied by a
// design — a grid of listed values, or a seeded random or Latin-hypercube design over lists and
// numeric ranges. Each case is the base scenario with its fields changed, validated by the
// scenario loader itself before anything is written or submitted.

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "study/field_path.hpp"

namespace mcopt::study {

enum class Design { Grid, Random, LatinHypercube };
/// "grid", "random", "latin-hypercube".
const char* toString(Design design);

/// A field set to one value in every case (`set:`).
struct FixedField {
  FieldPath path;
  YAML::Node value;
  std::string origin;  ///< "sweep.yaml:7: set.samples"
};

/// A varied field (`vary:`): a list of values (a grid's axis, or choices drawn by a random
/// design), or a numeric range [lower, upper] (random and Latin-hypercube designs only).
/// Fields listed under one `together:` share an axis (Sweep::axes): lists of one length, the
/// k-th values of all of them in the same case (a duration and the instants scaled with it).
struct VariedField {
  FieldPath path;
  std::vector<YAML::Node> values;
  std::vector<std::string> valueOrigins;  ///< "sweep.yaml:12: vary[0].values[1]"
  bool isRange = false;
  double lower = 0.0, upper = 0.0;
  bool logScale = false;  ///< log-uniform in the range (both ends positive)
  bool integer = false;   ///< values rounded to integers (samples, control points)
  std::string origin;     ///< "sweep.yaml:10: vary[0]"
};

/// What each case may use: OpenMP threads, a wall-time limit (0: none) and, on Slurm, the
/// memory asked for (sbatch --mem).
struct CaseResources {
  int threads = 1;
  double timeLimitSeconds = 0.0;
  std::string memory;  ///< "2G", "512M"; empty: the partition's default
};

struct SlurmSettings {
  std::string partition, account;
  std::vector<std::string> options;  ///< further sbatch options, verbatim
};

struct Sweep {
  std::filesystem::path file;          ///< the sweep file
  std::filesystem::path baseScenario;  ///< absolute
  std::string description;
  std::vector<FixedField> fixed;
  Design design = Design::Grid;
  std::size_t randomCases = 0;  ///< random and Latin-hypercube designs
  std::uint64_t seed = 1;
  std::vector<VariedField> varied;  ///< every varied field, axis by axis
  /// One per entry of `vary:`: its fields' indices in `varied` (several for `together:`).
  std::vector<std::vector<std::size_t>> axes;
  CaseResources resources;
  SlurmSettings slurm;
};

struct StudyCase {
  std::size_t index = 0;
  std::vector<YAML::Node> values;  ///< one per varied field, in the sweep's order
  YAML::Node scenario;             ///< the case's whole scenario, side-file paths absolute
};

/// Reads a sweep file. Throws InputError "file:line: field: what" for unknown keys, wrong
/// types, bad field paths and empty designs.
Sweep loadSweep(const std::filesystem::path& file);

/// The cases of the sweep's design, each with its scenario tree (not yet validated). A grid
/// runs through its axes' values with the first axis slowest; random and Latin-hypercube
/// designs draw from std::mt19937_64 seeded with `seed` (the same cases on every platform),
/// one draw an axis.
std::vector<StudyCase> designCases(const Sweep& sweep);

/// Loads every case's scenario with the scenario loader. A value the scenario refuses is
/// reported at its line in the sweep file ("sweep.yaml:12: vary[0].values[1]: …"), a
/// combination that only fails together at the case's values; throws InputError.
void validateCases(const Sweep& sweep, const std::vector<StudyCase>& cases);

/// A value as one line of text: a scalar as written, a list in flow style ([0.8, 0, 0]).
std::string valueText(const YAML::Node& value);

/// The scenario file written for a case: a comment naming the study, the case and its values,
/// then the scenario.
std::string caseScenarioText(const Sweep& sweep, const StudyCase& studyCase);

}  // namespace mcopt::study
