// SPDX-License-Identifier: BSD-3-Clause
#include "study/sweep.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <random>
#include <regex>
#include <stdexcept>

#include "core/errors.hpp"
#include "core/yaml_fields.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/scenario_yaml.hpp"
#include "study/scenario_tree.hpp"

namespace mcopt::study {

namespace {

using yaml::where;

std::string withoutColon(std::string origin) {
  if (origin.size() >= 2 && origin.compare(origin.size() - 2, 2, ": ") == 0) origin.resize(origin.size() - 2);
  return origin;
}

FieldPath fieldPath(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  try {
    return parseFieldPath(yaml::text(file, node, field));
  } catch (const std::invalid_argument& e) {
    throw InputError(where(file, node, field) + e.what());
  }
}

/// Seconds from a number or "[D-]HH:MM:SS" / "MM:SS" (Slurm's forms).
double timeLimit(const std::filesystem::path& file, const YAML::Node& node) {
  const std::string field = "resources.time";
  if (!node.IsScalar()) throw InputError(where(file, node, field) + "expected seconds or \"HH:MM:SS\"");
  const std::string text = node.Scalar();
  static const std::regex clock(R"(^(?:(\d+)-)?(?:(\d+):)?(\d+):(\d+)$)");
  std::smatch m;
  double seconds = 0.0;
  if (std::regex_match(text, m, clock)) {
    const auto part = [&](int k) { return m[k].matched ? std::stod(m[k].str()) : 0.0; };
    seconds = part(1) * 86400.0 + part(2) * 3600.0 + part(3) * 60.0 + part(4);
  } else {
    seconds = yaml::number(file, node, field);
  }
  if (seconds <= 0.0) throw InputError(where(file, node, field) + "must be positive");
  return seconds;
}

std::string shortest(double value) {
  char buffer[64];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, r.ptr);
}

/// The uniform draw on [0, 1) from 53 bits: the same numbers wherever std::mt19937_64 is
/// the same (the standard fixes its sequence; std::uniform_real_distribution is not fixed).
double unitDraw(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

YAML::Node drawnValue(const VariedField& f, double u) {
  if (!f.isRange) {
    const auto k = std::min(f.values.size() - 1, static_cast<std::size_t>(u * static_cast<double>(f.values.size())));
    return YAML::Clone(f.values[k]);
  }
  double x = f.logScale ? std::exp(std::log(f.lower) + u * (std::log(f.upper) - std::log(f.lower)))
                        : f.lower + u * (f.upper - f.lower);
  YAML::Node node;
  if (f.integer) node = static_cast<long long>(std::llround(x));
  else node = shortest(x);
  return node;
}

/// InputError messages of the scenario loader start with "base.yaml:LINE: "; for a value
/// changed by the sweep that line is meaningless, so the sweep's own line replaces it.
std::string withoutScenarioLocation(const std::string& message, const std::filesystem::path& scenario) {
  const std::string head = scenario.string() + ":";
  if (message.compare(0, head.size(), head) != 0) return message;
  const std::size_t colon = message.find(": ", head.size());
  return colon == std::string::npos ? message : message.substr(colon + 2);
}

/// The base scenario with side-file paths made absolute, so that a case written elsewhere
/// finds them.
YAML::Node baseTree(const Sweep& sweep) {
  const YAML::Node root = yaml::loadFile(sweep.baseScenario);
  if (!root.IsMap()) throw InputError(sweep.baseScenario.string() + ":1: expected a mapping of scenario fields");
  return withAbsoluteSideFiles(root, sweep.baseScenario);
}

void apply(YAML::Node root, const FieldPath& path, const YAML::Node& value, const std::string& origin) {
  try {
    setField(root, path, value);
  } catch (const std::invalid_argument& e) {
    throw InputError(origin + ": " + path.text + ": " + e.what());
  }
}

/// Loads a tree with the scenario loader; on a refusal, the message is placed at `origin`.
void check(const Sweep& sweep, const YAML::Node& root, const std::string& origin, const std::string& what) {
  try {
    (void)loadScenario(root, sweep.baseScenario);
  } catch (const InputError& e) {
    throw InputError(origin + ": " + what + ": the scenario refuses it: " + withoutScenarioLocation(e.what(), sweep.baseScenario));
  }
}

/// One entry of `vary:` (docs/reference/studies.md, "The sweep file").
VariedField readVariedField(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, bool grid) {
  yaml::rejectUnknownKeys(file, node, field, {"field", "values", "range", "scale", "integer"});
  VariedField f;
  f.origin = withoutColon(where(file, node, field));
  f.path = fieldPath(file, yaml::required(file, node, "field", field), field + ".field");
  if (node["values"] && node["range"]) throw InputError(where(file, node["range"], field + ".range") + "give values or a range, not both");
  if (const YAML::Node values = node["values"]) {
    if (!values.IsSequence()) throw InputError(where(file, values, field + ".values") + "expected a list of values");
    if (values.size() == 0) throw InputError(where(file, values, field + ".values") + "an empty list: no case would run");
    for (std::size_t j = 0; j < values.size(); ++j) {
      f.values.push_back(YAML::Clone(values[j]));
      f.valueOrigins.push_back(withoutColon(where(file, values[j], field + ".values[" + std::to_string(j) + "]")));
    }
  } else if (const YAML::Node range = node["range"]) {
    if (grid) throw InputError(where(file, range, field + ".range") + "a grid needs values: a range is for random and latin-hypercube designs");
    const auto r = yaml::numbers(file, range, field + ".range", 2);
    f.isRange = true, f.lower = r[0], f.upper = r[1];
    if (!(f.lower < f.upper)) throw InputError(where(file, range, field + ".range") + "expected lower < upper");
    f.valueOrigins = {withoutColon(where(file, range[0], field + ".range[0]")), withoutColon(where(file, range[1], field + ".range[1]"))};
    if (const YAML::Node scale = node["scale"]) {
      const std::string name = yaml::text(file, scale, field + ".scale");
      if (name != "linear" && name != "log") throw InputError(where(file, scale, field + ".scale") + "expected linear or log");
      f.logScale = name == "log";
      if (f.logScale && f.lower <= 0.0) throw InputError(where(file, range, field + ".range") + "a log scale needs a positive range");
    }
    if (const YAML::Node integer = node["integer"]) {
      try {
        f.integer = integer.as<bool>();
      } catch (const YAML::Exception&) {
        throw InputError(where(file, integer, field + ".integer") + "expected true or false");
      }
    }
  } else {
    throw InputError(where(file, node, field) + "give values (a list) or a range [lower, upper]");
  }
  if (!f.isRange && (node["scale"] || node["integer"]))
    throw InputError(where(file, node["scale"] ? node["scale"] : node["integer"], field) + "scale and integer apply to a range only");
  return f;
}

/// One entry of `vary:`: a field, or fields varied `together:` (lists of one length, the k-th
/// values in one case). Each field is checked against those read before it (`earlier`).
std::vector<VariedField> readAxis(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, bool grid,
                                  const std::vector<VariedField>& earlier) {
  std::vector<std::pair<YAML::Node, std::string>> entries;  // each field's node and its name in messages
  if (node.IsMap() && node["together"]) {
    yaml::rejectUnknownKeys(file, node, field, {"together"});
    const YAML::Node list = node["together"];
    if (!list.IsSequence() || list.size() < 2)
      throw InputError(where(file, list, field + ".together") + "expected a list of at least two fields, each with its values");
    for (std::size_t j = 0; j < list.size(); ++j) entries.emplace_back(list[j], field + ".together[" + std::to_string(j) + "]");
  } else {
    entries.emplace_back(node, field);
  }
  std::vector<VariedField> fields;
  const auto variedBefore = [&](const FieldPath& path) {
    const auto same = [&](const VariedField& other) { return other.path.text == path.text; };
    return std::any_of(earlier.begin(), earlier.end(), same) || std::any_of(fields.begin(), fields.end(), same);
  };
  for (const auto& [entry, name] : entries) {
    VariedField f = readVariedField(file, entry, name, grid);
    if (entries.size() > 1) {
      if (f.isRange) throw InputError(where(file, entry["range"], name + ".range") + "fields varied together list their values, not a range");
      if (!fields.empty() && f.values.size() != fields.front().values.size())
        throw InputError(where(file, entry["values"], name + ".values") + std::to_string(f.values.size()) + " values where " +
                         fields.front().path.text + " has " + std::to_string(fields.front().values.size()) +
                         ": fields varied together list as many values");
    }
    if (variedBefore(f.path)) throw InputError(where(file, entry["field"], name + ".field") + "'" + f.path.text + "' is varied twice");
    fields.push_back(std::move(f));
  }
  return fields;
}

/// The values a field is checked with on its own: its list, or a range's two ends.
std::vector<YAML::Node> probeValues(const VariedField& f) {
  if (!f.isRange) return f.values;
  std::vector<YAML::Node> ends;
  for (double end : {f.lower, f.upper}) {
    YAML::Node v;
    if (f.integer) v = static_cast<long long>(std::llround(end));
    else v = shortest(end);
    ends.push_back(v);
  }
  return ends;
}

}  // namespace

const char* toString(Design design) {
  switch (design) {
    case Design::Grid: return "grid";
    case Design::Random: return "random";
    case Design::LatinHypercube: return "latin-hypercube";
  }
  return "?";
}

std::string valueText(const YAML::Node& value) {
  if (value.IsScalar()) return value.Scalar();
  YAML::Emitter out;
  out << YAML::Flow << value;
  return out.c_str();
}

Sweep loadSweep(const std::filesystem::path& file) {
  const YAML::Node root = yaml::loadFile(file);
  if (!root.IsMap()) throw InputError(file.string() + ":1: expected a mapping of sweep fields");
  yaml::rejectUnknownKeys(file, root, "", {"description", "scenario", "set", "design", "cases", "seed", "vary", "resources", "slurm"});
  Sweep s;
  s.file = file;
  if (root["description"]) s.description = yaml::text(file, root["description"], "description");
  const YAML::Node scenarioNode = yaml::required(file, root, "scenario", "");
  // Relative to the sweep file, as a scenario's side files are to the scenario.
  s.baseScenario = std::filesystem::absolute(file.parent_path() / yaml::text(file, scenarioNode, "scenario")).lexically_normal();
  if (!std::filesystem::is_regular_file(s.baseScenario))
    throw InputError(where(file, scenarioNode, "scenario") + "file not found: " + s.baseScenario.string());

  if (const YAML::Node set = root["set"]) {
    if (!set.IsMap()) throw InputError(where(file, set, "set") + "expected a mapping of field paths to values");
    for (const auto& entry : set) {
      const std::string field = "set." + entry.first.as<std::string>();
      s.fixed.push_back({fieldPath(file, entry.first, field), YAML::Clone(entry.second), withoutColon(where(file, entry.second, field))});
    }
  }

  if (const YAML::Node design = root["design"]) {
    const std::string name = yaml::text(file, design, "design");
    if (name == "grid") s.design = Design::Grid;
    else if (name == "random") s.design = Design::Random;
    else if (name == "latin-hypercube") s.design = Design::LatinHypercube;
    else throw InputError(where(file, design, "design") + "unknown design '" + name + "' (expected grid, random, latin-hypercube)");
  }
  const bool grid = s.design == Design::Grid;
  if (const YAML::Node cases = root["cases"]) {
    if (grid) throw InputError(where(file, cases, "cases") + "a grid has one case per combination of values: cases is for random and latin-hypercube designs");
    const double n = yaml::number(file, cases, "cases");
    if (n != std::floor(n) || n < 1 || n > 1e6) throw InputError(where(file, cases, "cases") + "expected an integer ≥ 1");
    s.randomCases = static_cast<std::size_t>(n);
  } else if (!grid) {
    throw InputError(where(file, root, "cases") + "missing required field (the number of cases of a " + toString(s.design) + " design)");
  }
  if (const YAML::Node seed = root["seed"]) {
    const double v = yaml::number(file, seed, "seed");
    if (v != std::floor(v) || v < 0 || v > 9.0e15) throw InputError(where(file, seed, "seed") + "expected an integer ≥ 0");
    s.seed = static_cast<std::uint64_t>(v);
  }

  const YAML::Node vary = yaml::required(file, root, "vary", "");
  if (!vary.IsSequence()) throw InputError(where(file, vary, "vary") + "expected a list of fields to vary");
  if (vary.size() == 0) throw InputError(where(file, vary, "vary") + "an empty design: list at least one field to vary");
  for (std::size_t i = 0; i < vary.size(); ++i) {
    std::vector<std::size_t>& axis = s.axes.emplace_back();
    for (VariedField& f : readAxis(file, vary[i], "vary[" + std::to_string(i) + "]", grid, s.varied)) {
      axis.push_back(s.varied.size());
      s.varied.push_back(std::move(f));
    }
  }
  std::size_t combinations = 1;
  if (grid)
    for (const std::vector<std::size_t>& axis : s.axes) {
      combinations *= s.varied[axis.front()].values.size();
      if (combinations > 1000000) throw InputError(where(file, vary, "vary") + "a grid of more than a million cases");
    }

  if (const YAML::Node resources = root["resources"]) {
    yaml::rejectUnknownKeys(file, resources, "resources", {"threads", "time", "memory"});
    if (resources["threads"]) {
      const double t = yaml::number(file, resources["threads"], "resources.threads");
      if (t != std::floor(t) || t < 1 || t > 1024) throw InputError(where(file, resources["threads"], "resources.threads") + "expected an integer ≥ 1");
      s.resources.threads = static_cast<int>(t);
    }
    if (resources["time"]) s.resources.timeLimitSeconds = timeLimit(file, resources["time"]);
    if (resources["memory"]) {
      s.resources.memory = yaml::text(file, resources["memory"], "resources.memory");
      if (!std::regex_match(s.resources.memory, std::regex(R"(^[1-9][0-9]*[KMGT]?$)")))
        throw InputError(where(file, resources["memory"], "resources.memory") + "expected a size as Slurm writes it: 512M, 2G");
    }
  }
  if (const YAML::Node slurm = root["slurm"]) {
    yaml::rejectUnknownKeys(file, slurm, "slurm", {"partition", "account", "options"});
    if (slurm["partition"]) s.slurm.partition = yaml::text(file, slurm["partition"], "slurm.partition");
    if (slurm["account"]) s.slurm.account = yaml::text(file, slurm["account"], "slurm.account");
    if (const YAML::Node options = slurm["options"]) {
      if (!options.IsSequence()) throw InputError(where(file, options, "slurm.options") + "expected a list of sbatch options");
      for (std::size_t k = 0; k < options.size(); ++k) {
        const std::string option = yaml::text(file, options[k], "slurm.options[" + std::to_string(k) + "]");
        if (option.rfind("--", 0) != 0 || option.find('\n') != std::string::npos)
          throw InputError(where(file, options[k], "slurm.options[" + std::to_string(k) + "]") + "expected one sbatch option, --name=value");
        s.slurm.options.push_back(option);
      }
    }
  }
  return s;
}

std::vector<StudyCase> designCases(const Sweep& sweep) {
  YAML::Node base = baseTree(sweep);
  for (const FixedField& f : sweep.fixed) apply(base, f.path, f.value, f.origin);
  const std::vector<std::vector<std::size_t>>& axes = sweep.axes;
  std::vector<std::vector<YAML::Node>> rows;
  if (sweep.design == Design::Grid) {
    std::size_t count = 1;
    for (const auto& axis : axes) count *= sweep.varied[axis.front()].values.size();
    for (std::size_t k = 0; k < count; ++k) {
      std::vector<YAML::Node> row(sweep.varied.size());
      std::size_t rest = k;
      for (std::size_t a = axes.size(); a-- > 0;) {  // the last axis fastest
        const std::size_t n = sweep.varied[axes[a].front()].values.size();
        for (std::size_t i : axes[a]) row[i] = YAML::Clone(sweep.varied[i].values[rest % n]);
        rest /= n;
      }
      rows.push_back(std::move(row));
    }
  } else {
    std::mt19937_64 rng(sweep.seed);
    const std::size_t n = sweep.randomCases;
    rows.assign(n, std::vector<YAML::Node>(sweep.varied.size()));
    for (const auto& axis : axes) {
      // Latin hypercube: each axis's n strata [k/n, (k+1)/n) used once, in a random order
      // (Fisher–Yates on the engine's own integers, for the same order on every platform).
      // Fields varied together share the draw, hence the index into their lists.
      std::vector<std::size_t> strata(n);
      for (std::size_t k = 0; k < n; ++k) strata[k] = k;
      if (sweep.design == Design::LatinHypercube)
        for (std::size_t k = n; k-- > 1;) std::swap(strata[k], strata[rng() % (k + 1)]);
      for (std::size_t k = 0; k < n; ++k) {
        const double u = sweep.design == Design::LatinHypercube
                             ? (static_cast<double>(strata[k]) + unitDraw(rng)) / static_cast<double>(n)
                             : unitDraw(rng);
        for (std::size_t i : axis) rows[k][i] = drawnValue(sweep.varied[i], u);
      }
    }
  }
  std::vector<StudyCase> cases;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    StudyCase c;
    c.index = k;
    c.values = std::move(rows[k]);
    c.scenario = YAML::Clone(base);
    for (std::size_t i = 0; i < sweep.varied.size(); ++i) apply(c.scenario, sweep.varied[i].path, c.values[i], sweep.varied[i].origin);
    cases.push_back(std::move(c));
  }
  return cases;
}

void validateCases(const Sweep& sweep, const std::vector<StudyCase>& cases) {
  const YAML::Node plain = baseTree(sweep);
  check(sweep, plain, sweep.baseScenario.string(), "the base scenario");
  YAML::Node base = YAML::Clone(plain);
  for (const FixedField& f : sweep.fixed) {
    YAML::Node single = YAML::Clone(plain);
    apply(single, f.path, f.value, f.origin);
    check(sweep, single, f.origin, f.path.text + " = " + valueText(f.value));
    apply(base, f.path, f.value, f.origin);
  }
  if (sweep.fixed.size() > 1) check(sweep, base, sweep.fixed.front().origin, "the set fields together");
  // Each value on its own first (with the values varied together with it), so that a refusal
  // points at the value's line.
  for (const std::vector<std::size_t>& axis : sweep.axes) {
    std::vector<std::vector<YAML::Node>> probes;  // per field of the axis, lists of one length
    for (std::size_t i : axis) probes.push_back(probeValues(sweep.varied[i]));
    const VariedField& first = sweep.varied[axis.front()];
    for (std::size_t j = 0; j < probes.front().size(); ++j) {
      YAML::Node single = YAML::Clone(base);
      std::string what;
      for (std::size_t a = 0; a < axis.size(); ++a) {
        const VariedField& f = sweep.varied[axis[a]];
        const YAML::Node& value = probes[a][j];
        apply(single, f.path, value, f.valueOrigins[j]);
        what += (what.empty() ? "" : ", ") + f.path.text + " = " + valueText(value);
      }
      check(sweep, single, first.valueOrigins[j], what);
    }
  }
  for (const StudyCase& c : cases) {
    std::string values;
    for (std::size_t i = 0; i < sweep.varied.size(); ++i)
      values += (i == 0 ? "" : ", ") + sweep.varied[i].path.text + " = " + valueText(c.values[i]);
    check(sweep, c.scenario, sweep.varied.front().origin, "case " + std::to_string(c.index) + " (" + values + ")");
  }
}

std::string caseScenarioText(const Sweep& sweep, const StudyCase& studyCase) {
  std::string text = "# Case " + std::to_string(studyCase.index) + " of the study " + sweep.file.string() + "\n# base scenario " +
                     sweep.baseScenario.string() + "\n";
  for (std::size_t i = 0; i < sweep.varied.size(); ++i)
    text += "# " + sweep.varied[i].path.text + " = " + valueText(studyCase.values[i]) + "\n";
  YAML::Emitter out;
  out << studyCase.scenario;
  return text + out.c_str() + "\n";
}

}  // namespace mcopt::study
