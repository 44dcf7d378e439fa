# SPDX-License-Identifier: BSD-3-Clause
"""`mcopt replay` (docs/guides/replay.md) as a person uses it: the page opened in headless Chromium
from a file:// URL at two instants, with no console error, two screenshots that are neither
blank nor equal, and the robot where its pose puts it — every body at the position our own
kinematics (mcopt.Dynamics, not the page's scene) gives for the result's q at that instant,
and drawn at the pixel the page projects it to."""
import json
import os
import pathlib
import re
import shutil
import subprocess
import xml.etree.ElementTree

import matplotlib.image
import numpy as np
import pytest

import mcopt
from conftest import HRP2, SOURCE, cli_error, run_cli

KICK = SOURCE / "scenarios" / "hrp2_kick.yaml"
BACKGROUND = np.array([0xEE, 0xF1, 0xF5]) / 255.0  # the page's background colour


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    pytest.fail("headless Chromium is needed (Debian's chromium; scripts/install-deps.sh installs it)")


def open_page(page, fragment, tmp_path, tag):
    """Opens page#fragment headless: (state the page reports, screenshot RGB, console lines)."""
    url = page.resolve().as_uri() + fragment
    common = [chromium(), "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
              "--window-size=1000,700", "--virtual-time-budget=3000", "--enable-logging=stderr", "--v=0",
              f"--user-data-dir={tmp_path / ('profile-' + tag)}"]
    shot = tmp_path / f"{tag}.png"
    # One launch takes both the screenshot and the DOM after the virtual-time budget (Debian's
    # headless Chromium does both in one run; two launches a page cost the CI ~2 s each).
    done = subprocess.run(common + [f"--screenshot={shot}", "--dump-dom", url], capture_output=True, text=True,
                          timeout=120)
    assert shot.exists(), done.stderr[-2000:]
    console = [l for l in done.stderr.splitlines() if ":CONSOLE" in l]
    match = re.search(r'<pre id="mcopt-state"[^>]*>(.*?)</pre>', done.stdout, re.S)
    assert match and match.group(1), "the page reported no state (it did not render):\n" + done.stderr[-2000:]
    image = matplotlib.image.imread(shot)[:, :, :3]
    return json.loads(match.group(1)), image, console


@pytest.fixture(scope="module")
def replayed(mcopt_exe, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("replay")
    s = mcopt.Scenario(KICK)
    s["samples"] = 30
    s.save(tmp / "kick.yaml")
    run_cli(mcopt_exe, "run", tmp / "kick.yaml", "--max-iterations", 25, "--out", tmp / "kick", check=False)
    _, out, _ = run_cli(mcopt_exe, "replay", tmp / "kick", "--out", tmp / "kick.html")
    assert str(tmp / "kick.html") in out
    return tmp, json.loads((tmp / "kick" / "result.json").read_text()), tmp / "kick.html"


def test_the_page_is_one_file_that_loads_nothing(replayed):
    _, _, page = replayed
    html = page.read_text()
    assert not re.search(r"<script[^>]*\ssrc=", html), "a script is loaded from elsewhere"
    assert not re.search(r"<link[^>]*\shref=", html), "a style sheet or resource is loaded from elsewhere"
    assert "THREE.OrbitControls" in html or "OrbitControls" in html
    assert page.stat().st_size < 3 * 1024 * 1024


def kinematics(result):
    robot = mcopt.Robot(HRP2 / "hrp2.urdf")
    pose = result["reference_pose"]
    return mcopt.Dynamics(robot, result["reference_body"], reference_position=pose["position"],
                          reference_quaternion_xyzw=pose["quaternion_xyzw"], gravity=result["gravity"])


def body_mass_properties():
    """Each link's centre of mass in its frame and its mass, read from the URDF itself (HRP-2's
    links fixed to others — soles, palms, head top — are massless, so a body's are its link's)."""
    com, mass = {}, {}
    for link in xml.etree.ElementTree.parse(HRP2 / "hrp2.urdf").getroot().iter("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        origin = inertial.find("origin")
        com[link.get("name")] = np.array([float(v) for v in origin.get("xyz").split()]) if origin is not None else np.zeros(3)
        mass[link.get("name")] = float(inertial.find("mass").get("value"))
    return com, mass


def projector(camera, width, height):
    """World point → pixel of a canvas width × height at the top left of the screenshot, for the
    page's perspective camera (three.js's lookAt and projection conventions)."""
    eye, target, up = (np.array(camera[k], float) for k in ("position", "target", "up"))
    back = (eye - target) / np.linalg.norm(eye - target)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    true_up = np.cross(back, right)
    f = 1.0 / np.tan(np.radians(camera["fov_deg"]) / 2)

    def pixel(point):
        d = np.asarray(point, float) - eye
        x, y, z = d @ right, d @ true_up, d @ back
        ndc = np.array([f / (width / height) * x / -z, f * y / -z])
        return [(ndc[0] + 1) / 2 * width, (1 - ndc[1]) / 2 * height]
    return pixel


def drawn_at(image, xy):
    """Whether the pixels around a screen point differ from the background."""
    x, y = int(round(xy[0])), int(round(xy[1]))
    patch = image[max(y - 2, 0):y + 3, max(x - 2, 0):x + 3]
    return bool(patch.size) and float(np.abs(patch - BACKGROUND).max()) > 0.08


def test_two_instants_in_headless_chromium(replayed):
    tmp, result, page = replayed
    times = result["time"]
    middle = len(times) // 2
    dynamics = kinematics(result)
    robot_com, robot_mass = body_mass_properties()
    views = {}
    for tag, k in (("start", 0), ("middle", middle)):
        state, image, console = open_page(page, f"#t={times[k]!r}", tmp, tag)
        # The canvas fills the window above the 56-pixel control bar.
        pixel = projector(state["camera"], image.shape[1], image.shape[0] - 56)
        assert console == [], "console output: " + "\n".join(console)
        assert state["errors"] == []
        assert not state["playing"], "#t= opens the page paused"
        assert state["t"] == pytest.approx(times[k], abs=1e-12)
        assert state["frames"] >= 1
        # Neither blank: the robot, floor and controls cover a good part of the view.
        assert float((np.abs(image - BACKGROUND).max(axis=2) > 0.08).mean()) > 0.05, f"{tag}: the screenshot is blank"
        # Every body where our kinematics puts it for the result's q at this sample.
        q = np.array(result["q"][k])
        for name, body in state["bodies"].items():
            position, rotation = dynamics.frame_pose(name, q)
            assert np.allclose(body["position"], position, atol=2e-5), f"{tag}: {name} drawn at {body['position']}, is at {position}"
            x, y, z, w = body["quaternion_xyzw"]
            drawn = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                              [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                              [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
            assert np.allclose(drawn, rotation, atol=1e-4), f"{tag}: {name} drawn turned otherwise than its pose"
            # Its first shape (the inertia box: HRP-2's URDF has no visual) sits at the body's
            # centre of mass, which our model gives in the body frame.
            com = robot_com[name]
            assert np.allclose(body["shape_centre"], position + rotation @ com, atol=1e-4), f"{tag}: {name}'s shape misplaced"
            if robot_mass[name] > 0.3:
                assert drawn_at(image, pixel(position + rotation @ com)), f"{tag}: nothing drawn at {name}'s centre of mass"
        # …and drawn there: the bodies that carry others have a link cylinder from their
        # origin, so their origin is never empty space.
        carried = [name for name in state["bodies"] if name.endswith(("LINK0", "LINK1", "LINK2", "LINK3")) or name == "BODY"]
        assert carried
        for name in carried:
            assert drawn_at(image, pixel(dynamics.frame_pose(name, q)[0])), f"{tag}: nothing drawn at {name}'s origin"
        # …and not everywhere: 0.7 m to the robot's left, at its chest, is empty (in view).
        beside = pixel(dynamics.frame_pose("CHEST_LINK1", q)[0] + [0.0, 0.7, 0.0])
        assert 0 < beside[0] < image.shape[1] and 40 < beside[1] < image.shape[0] - 56
        assert not drawn_at(image, beside), f"{tag}: something drawn beside the robot"
        state["foot_pixel"] = pixel(dynamics.frame_pose("RLEG_LINK5", q)[0])
        views[tag] = (state, image)
    (start, first), (middle_state, second) = views["start"], views["middle"]
    assert first.shape == second.shape
    assert float(np.abs(first - second).max(axis=2).mean()) > 1e-3, "the two instants look the same"
    # The kicking foot moved on the screen as its pose says.
    moved = np.subtract(middle_state["foot_pixel"], start["foot_pixel"])
    assert np.linalg.norm(moved) > 5.0, f"the right foot moved {moved} px"
    assert drawn_at(second, middle_state["foot_pixel"]) and drawn_at(first, start["foot_pixel"])


def test_without_fragment_it_plays(replayed):
    tmp, _, page = replayed
    state, _, console = open_page(page, "", tmp, "playing")
    assert console == [] and state["errors"] == []
    assert state["playing"]


def test_a_fragment_beyond_the_motion_opens_at_its_end(replayed):
    tmp, result, page = replayed
    state, _, _ = open_page(page, "#t=99", tmp, "beyond")
    assert state["t"] == pytest.approx(result["duration"]) and not state["playing"]


def test_results_it_cannot_draw_are_refused_with_the_field(mcopt_exe, replayed, tmp_path):
    _, result, _ = replayed
    (tmp_path / "old").mkdir()
    old = dict(result)
    del old["robot_files"]
    (tmp_path / "old" / "result.json").write_text(json.dumps(old))
    message = cli_error(mcopt_exe, "replay", tmp_path / "old")
    assert message == f"{tmp_path / 'old' / 'result.json'}: robot_files: missing (a result of an older mcopt run? run it again)"
    assert not (tmp_path / "old" / "replay.html").exists()

    (tmp_path / "other").mkdir()
    other = dict(result)
    other["joint_names"] = list(reversed(result["joint_names"]))
    (tmp_path / "other" / "result.json").write_text(json.dumps(other))
    message = cli_error(mcopt_exe, "replay", tmp_path / "other")
    assert message.startswith(f"{tmp_path / 'other' / 'result.json'}: joint_names[0]: ")

    (tmp_path / "empty").mkdir()
    assert cli_error(mcopt_exe, "replay", tmp_path / "empty") == \
        f"{tmp_path / 'empty' / 'result.json'}: file not found (give the folder `mcopt run --out` wrote)"


def test_a_throw_shows_the_ball_in_the_hand_then_on_its_flight(mcopt_exe, tmp_path):
    """The throw's ball (issue 15): where our kinematics puts the hand's point before the
    release, on the flight result.json's release state gives after it, drawn there, and
    resting at the landing point at the end."""
    s = mcopt.Scenario(SOURCE / "scenarios" / "hrp2_throw.yaml")
    s.save(tmp_path / "throw.yaml")
    run_cli(mcopt_exe, "run", tmp_path / "throw.yaml", "--max-iterations", 4, "--out", tmp_path / "throw", check=False)
    run_cli(mcopt_exe, "replay", tmp_path / "throw", "--out", tmp_path / "throw.html")
    result = json.loads((tmp_path / "throw" / "result.json").read_text())
    release = result["release"]
    dynamics = kinematics(result)
    k = 10  # t = 0.4 s, the ball in the hand
    state, image, console = open_page(tmp_path / "throw.html", f"#t={result['time'][k]!r}", tmp_path, "carried")
    assert console == [] and state["errors"] == []
    position, rotation = dynamics.frame_pose(release["body"], np.array(result["q"][k]))
    # The scene keeps positions to 1e-5 m (apps/replay_scene.cpp), as the bodies' (atol 2e-5 above).
    assert np.allclose(state["ball"], position + rotation @ np.array(release["point"]), atol=2e-5)
    pixel = projector(state["camera"], image.shape[1], image.shape[0] - 56)
    assert drawn_at(image, pixel(np.array(state["ball"])))
    g = np.array(result["gravity"])
    for tag, tau in (("flying", 0.5 * release["flight_time"]), ("landed", release["flight_time"])):
        t = release["time"] + tau
        state, image, console = open_page(tmp_path / "throw.html", f"#t={t!r}", tmp_path, tag)
        assert console == [] and state["errors"] == []
        expected = np.array(release["position"]) + np.array(release["velocity"]) * tau + 0.5 * g * tau * tau
        assert np.allclose(state["ball"], expected, atol=2e-5), f"{tag}: ball at {state['ball']}, flies through {expected}"
        pixel = projector(state["camera"], image.shape[1], image.shape[0] - 56)
        xy = pixel(expected)
        if 0 < xy[0] < image.shape[1] and 0 < xy[1] < image.shape[0] - 56:
            assert drawn_at(image, xy), f"{tag}: nothing drawn at the ball"
    assert np.allclose(expected, release["landing_point"], atol=1e-6)


def test_the_instants_verify_found_broken_are_marked(mcopt_exe, replayed, tmp_path):
    """With verify.json beside the result (docs/reference/verify.md), its failing instants are ticks
    on the timeline, named where the page stands; a bad verify.json is refused with its field."""
    tmp, result, _ = replayed
    folder = tmp_path / "kick"
    shutil.copytree(tmp / "kick", folder)
    verify = {"passed": False, "checks": [
        {"kind": "torque_limit", "passed": False, "failing_times": [0.4, 0.8]},
        {"kind": "contact_cop", "passed": False, "failing_times": [0.8]},
        {"kind": "task", "passed": True, "failing_times": []}]}
    (folder / "verify.json").write_text(json.dumps(verify))
    _, out, _ = run_cli(mcopt_exe, "replay", folder, "--out", tmp_path / "marked.html")
    assert "2 instants where a check is broken" in out
    state, _, console = open_page(tmp_path / "marked.html", "#t=0.8", tmp_path, "marked")
    assert console == [] and state["errors"] == []
    assert state["verify"]["marks"] == [0.4, 0.8] and state["verify"]["passed"] is False
    assert "here, t = 0.800 s: torque_limit, contact_cop" in state["verify"]["shown"]
    html = (tmp_path / "marked.html").read_text()
    assert '"verify":{"marks":[{"checks":["torque_limit"],"time":0.4}' in html
    (folder / "verify.json").write_text(json.dumps({"passed": False, "checks": [{"kind": "task", "failing_times": ["soon"]}]}))
    code, _, err = run_cli(mcopt_exe, "replay", folder, "--out", tmp_path / "refused.html", check=False)
    assert code == 2 and "verify.json: checks[0].failing_times[0]: expected a number" in err
    assert not (tmp_path / "refused.html").exists()
