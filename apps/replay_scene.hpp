// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The scene of a replay (docs/guides/replay.md): what the page draws at each sample of a result —
// every body's world pose, every contact's frame, wrench and centre of pressure in world
// axes, the centre of mass — computed here by our own kinematics, so that the page only
// places what it is given.

#include <filesystem>
#include <nlohmann/json.hpp>

namespace mcopt::cli {

/// From a result.json of `mcopt run` (read from `resultFile`, named in errors) and the robot
/// files it names (`robot_files`): bodies with their shapes and poses per sample
/// (position, quaternion xyzw), contacts with rectangle, activity, world pose, force and
/// centre of pressure per sample, the centre of mass, the floor's height (the reference
/// contact's at the first sample). Throws InputError naming the file and field for a
/// result that lacks what the scene needs or does not match its robot.
nlohmann::json replayScene(const nlohmann::json& result, const std::filesystem::path& resultFile);

}  // namespace mcopt::cli
