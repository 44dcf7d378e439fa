// SPDX-License-Identifier: BSD-3-Clause
// `mcopt replay RESULT_DIR [--out FILE.html]`: one self-contained page that animates a
// result in 3-D with three.js (docs/guides/replay.md). The page holds everything it needs — three.js,
// its orbit controls, the scene, the viewer — so that it opens offline from a file:// URL.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "apps/commands.hpp"
#include "apps/data_paths.hpp"
#include "apps/json_io.hpp"
#include "apps/replay_scene.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"

namespace mcopt::cli {

namespace {

struct ReplayOptions {
  std::string result, out;
};

std::string fileText(const std::filesystem::path& path, const std::string& whatFor) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot read " + whatFor);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// three.js from Debian's libjs-three (or the folder MCOPT_THREE_JS_DIR names, e.g. npm's
/// node_modules/three with its build/ and examples/js/).
std::filesystem::path threeDirectory() {
  if (const char* chosen = std::getenv("MCOPT_THREE_JS_DIR"); chosen && *chosen) return chosen;
  return MCOPT_THREE_JS_DIR;
}

/// Replaces the one `@KEY@` of the template. A script's text may not hold "</script", or it
/// would end its element early; JSON escapes it as "<\/".
void fill(std::string& page, const std::string& key, const std::string& value) {
  const std::string marker = "@" + key + "@";
  const std::size_t at = page.find(marker);
  if (at == std::string::npos) throw std::logic_error("replay template lacks " + marker);
  page.replace(at, marker.size(), value);
}

std::string scriptText(std::string text, const std::filesystem::path& origin) {
  if (text.find("</script") != std::string::npos) throw InputError(origin.string() + ": holds \"</script\" and cannot be inlined");
  return text;
}

/// verify.json (docs/reference/verify.md) as the page's marks: its verdict and, per instant at
/// which a check is broken, the checks broken there.
nlohmann::json verifyMarks(const nlohmann::json& verify, const std::filesystem::path& file) {
  if (!verify.is_object() || !verify.contains("passed") || !verify["passed"].is_boolean())
    throw InputError(file.string() + ": passed: expected true or false (not a verify.json of mcopt verify?)");
  if (!verify.contains("checks") || !verify["checks"].is_array()) throw InputError(file.string() + ": checks: expected a list");
  std::map<double, std::vector<std::string>> broken;
  for (std::size_t c = 0; c < verify["checks"].size(); ++c) {
    const nlohmann::json& check = verify["checks"][c];
    const std::string field = "checks[" + std::to_string(c) + "]";
    if (!check.is_object() || !check.contains("kind") || !check["kind"].is_string())
      throw InputError(file.string() + ": " + field + ".kind: expected a name");
    if (!check.contains("failing_times")) throw InputError(file.string() + ": " + field + ".failing_times: missing");
    const Eigen::VectorXd times = json_io::numbers(file, check["failing_times"], field + ".failing_times");
    for (const double t : times) broken[t].push_back(check["kind"].get<std::string>());
  }
  nlohmann::json marks = nlohmann::json::array();
  for (const auto& [time, kinds] : broken) marks.push_back({{"time", time}, {"checks", kinds}});
  return {{"passed", verify["passed"].get<bool>()}, {"marks", marks}};
}

int replay(const ReplayOptions& o) {
  const std::filesystem::path resultFile = std::filesystem::path(o.result) / "result.json";
  if (!std::filesystem::is_regular_file(resultFile))
    throw InputError(resultFile.string() + ": file not found (give the folder `mcopt run --out` wrote)");
  nlohmann::json scene = replayScene(json_io::readFile(resultFile), resultFile);
  // `mcopt verify`'s findings beside the result: the instants it found broken, marked on the timeline.
  const std::filesystem::path verifyFile = std::filesystem::path(o.result) / "verify.json";
  if (std::filesystem::exists(verifyFile)) scene["verify"] = verifyMarks(json_io::readFile(verifyFile), verifyFile);

  const std::filesystem::path three = threeDirectory();
  const std::filesystem::path threeScript = three / "three.min.js";
  const std::filesystem::path orbitScript = three / "examples" / "js" / "controls" / "OrbitControls.js";
  if (!std::filesystem::is_regular_file(threeScript) || !std::filesystem::is_regular_file(orbitScript))
    throw InputError(threeScript.string() + ": three.js not found (install Debian's libjs-three, or set MCOPT_THREE_JS_DIR to a folder with three.min.js and examples/js/controls/OrbitControls.js)");
  const std::filesystem::path viewer = replayViewerDirectory();

  std::string page = fileText(viewer / "viewer.html", "the replay page's template");
  std::string sceneText = scene.dump();
  for (std::size_t at = sceneText.find("</"); at != std::string::npos; at = sceneText.find("</", at + 3)) sceneText.replace(at, 2, "<\\/");
  const std::string title = "mcopt replay: " + scene["scenario"].get<std::string>();
  std::string escapedTitle;
  for (char c : title) escapedTitle += c == '<' ? std::string("&lt;") : c == '&' ? std::string("&amp;") : std::string(1, c);
  // Last marker first: each is then found before any text already put in.
  fill(page, "VIEWER", scriptText(fileText(viewer / "viewer.js", "the replay viewer"), viewer / "viewer.js"));
  fill(page, "ORBIT_CONTROLS", scriptText(fileText(orbitScript, "three.js's orbit controls"), orbitScript));
  fill(page, "THREE", scriptText(fileText(threeScript, "three.js"), threeScript));
  fill(page, "SCENE", sceneText);
  fill(page, "TITLE", escapedTitle);

  const std::filesystem::path out = o.out.empty() ? std::filesystem::path(o.result) / "replay.html" : std::filesystem::path(o.out);
  writeFileAtomically(out, page);
  std::cout << "mcopt replay " << o.result << "\n" << out.string() << " (" << page.size() / 1024 << " KiB, " << scene["time"].size()
            << " samples; open it in a browser, #t=SECONDS opens it paused at that instant)\n";
  if (scene.contains("verify"))
    std::cout << "  " << verifyFile.string() << ": " << scene["verify"]["marks"].size()
              << " instants where a check is broken, marked on the timeline (n / p: the next / previous)\n";
  return 0;
}

}  // namespace

Runner addReplay(CLI::App& command) {
  auto o = std::make_shared<ReplayOptions>();
  command.add_option("result", o->result, "a result folder of mcopt run (with result.json)")->required()->check(CLI::ExistingDirectory);
  command.add_option("--out", o->out, "the HTML file to write (default RESULT/replay.html)");
  return [o] { return replay(*o); };
}

}  // namespace mcopt::cli
