#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Writes hrp2.urdf and the parameter table of README.md from the one table below.

Every number carries its source or estimation method (column `source`). Published facts
come from ../../../shared/docs/hrp2-facts.md (robot documentation and the report §1.3);
everything else is an estimate, named as such. Run: python3 generate_hrp2.py
"""
import math
import pathlib

HERE = pathlib.Path(__file__).resolve().parent

# --- Published facts -------------------------------------------------------------------
FACT = "published (hrp2-facts.md)"
RANGES = {  # joint ranges [rad], hrp2-facts.md
    "RLEG_JOINT0": (-0.785, 0.524), "LLEG_JOINT0": (-0.524, 0.785),
    "RLEG_JOINT1": (-0.611, 0.349), "LLEG_JOINT1": (-0.349, 0.611),
    "RLEG_JOINT2": (-2.182, 0.733), "LLEG_JOINT2": (-2.182, 0.733),
    "RLEG_JOINT3": (-0.035, 2.618), "LLEG_JOINT3": (-0.035, 2.618),
    "RLEG_JOINT4": (-1.309, 0.733), "LLEG_JOINT4": (-1.309, 0.733),
    "RLEG_JOINT5": (-0.349, 0.611), "LLEG_JOINT5": (-0.611, 0.349),
    "CHEST_JOINT0": (-0.785, 0.785), "CHEST_JOINT1": (-0.087, 1.047),
    "HEAD_JOINT0": (-0.785, 0.785), "HEAD_JOINT1": (-0.524, 0.785),
    "RARM_JOINT0": (-3.142, 1.047), "LARM_JOINT0": (-3.142, 1.047),
    "RARM_JOINT1": (-1.658, 0.175), "LARM_JOINT1": (-0.175, 1.658),
    "RARM_JOINT2": (-1.606, 1.606), "LARM_JOINT2": (-1.606, 1.606),
    "RARM_JOINT3": (-2.391, 0.035), "LARM_JOINT3": (-2.391, 0.035),
    "RARM_JOINT4": (-1.606, 1.606), "LARM_JOINT4": (-1.606, 1.606),
    "RARM_JOINT5": (-1.606, 1.606), "LARM_JOINT5": (-1.606, 1.606),
    "RARM_JOINT6": (-1.0, 1.0), "LARM_JOINT6": (-1.0, 1.0),
}
SOLE_BELOW_ANKLE = 0.105   # published: sole 0.105 m below the ankle axes
HEIGHT = 1.54              # published: 1.54 m
TOTAL_MASS = 58.0          # published: 58 kg with batteries

# --- Estimated geometry (zero posture: legs straight, arms down, x forward, z up) -------
# Proportions chosen so that the zero posture stands HEIGHT tall; each is an estimate.
HIP_Y = 0.06       # lateral hip offset; estimate from the 621 mm published width and leg spacing
THIGH = 0.30       # hip-pitch to knee; estimate, JVRC-1 (same lab, same size) has 0.30–0.40
SHANK = 0.30       # knee to ankle; estimate, as thigh
CHEST_Z = 0.35     # waist (hip joints) to chest joints; estimate from proportions
SHOULDER_Z = 0.18  # chest joints to shoulder axes; estimate from proportions
SHOULDER_Y = 0.25  # shoulder axis lateral offset; estimate: 621 mm width minus arm thickness
NECK_Z = 0.30      # chest joints to neck joints; estimate
HEAD_TOP = HEIGHT - (SOLE_BELOW_ANKLE + SHANK + THIGH + CHEST_Z + NECK_Z)  # closes the published height
UPPER_ARM = 0.25   # shoulder to elbow; estimate from proportions
FOREARM = 0.25     # elbow to wrist; estimate
HAND_TO_GRIPPER = 0.08  # wrist pitch axis to gripper axis; estimate
EST_GEOM = "estimate: proportions closing the published 1.54 m height"
EST_MASS = "estimate: share of the published 58 kg"
EST_BOX = "estimate: solid box of the link's envelope"

# Links: name, parent joint, mass [kg] and mass source, box size [m], box centre in link frame.
# Masses add up to the published 58 kg (checked below).
LINKS = {
    "BODY":         (9.0, (0.20, 0.26, 0.20), (0.0, 0.0, 0.10)),
    "CHEST_LINK0":  (1.0, (0.12, 0.12, 0.06), (0.0, 0.0, 0.0)),
    "CHEST_LINK1":  (16.0, (0.24, 0.34, 0.36), (-0.02, 0.0, 0.16)),
    "HEAD_LINK0":   (0.4, (0.06, 0.06, 0.06), (0.0, 0.0, 0.0)),
    "HEAD_LINK1":   (2.0, (0.18, 0.16, HEAD_TOP), (0.01, 0.0, HEAD_TOP / 2)),
}
for side in "RL":
    LINKS.update({
        f"{side}LEG_LINK0": (1.0, (0.10, 0.08, 0.06), (0.0, 0.0, 0.0)),
        f"{side}LEG_LINK1": (1.0, (0.10, 0.08, 0.06), (0.0, 0.0, 0.0)),
        f"{side}LEG_LINK2": (3.8, (0.12, 0.10, THIGH), (0.0, 0.0, -THIGH / 2)),
        f"{side}LEG_LINK3": (2.2, (0.10, 0.09, SHANK), (0.0, 0.0, -SHANK / 2)),
        f"{side}LEG_LINK4": (0.6, (0.06, 0.06, 0.06), (0.0, 0.0, 0.0)),
        f"{side}LEG_LINK5": (1.4, (0.23, 0.13, SOLE_BELOW_ANKLE), (0.02, 0.0, -SOLE_BELOW_ANKLE / 2)),
        f"{side}ARM_LINK0": (0.9, (0.08, 0.08, 0.08), (0.0, 0.0, 0.0)),
        f"{side}ARM_LINK1": (0.9, (0.08, 0.08, 0.08), (0.0, 0.0, 0.0)),
        f"{side}ARM_LINK2": (1.1, (0.08, 0.08, UPPER_ARM), (0.0, 0.0, -UPPER_ARM / 2)),
        f"{side}ARM_LINK3": (0.9, (0.07, 0.07, FOREARM), (0.0, 0.0, -FOREARM / 2)),
        f"{side}ARM_LINK4": (0.4, (0.05, 0.05, 0.05), (0.0, 0.0, 0.0)),
        f"{side}ARM_LINK5": (0.4, (0.08, 0.05, 0.12), (0.0, 0.0, -0.06)),
        f"{side}ARM_LINK6": (0.2, (0.03, 0.04, 0.08), (0.0, 0.0, -0.04)),
    })

# Joints: name, parent link, child link, origin in parent link frame, axis (OpenHRP layout).
JOINTS = []
for side, sign in (("R", -1.0), ("L", 1.0)):
    leg = [
        (f"{side}LEG_JOINT0", "BODY", (0.0, sign * HIP_Y, 0.0), (0, 0, 1)),          # hip yaw
        (f"{side}LEG_JOINT1", f"{side}LEG_LINK0", (0.0, 0.0, 0.0), (1, 0, 0)),         # hip roll
        (f"{side}LEG_JOINT2", f"{side}LEG_LINK1", (0.0, 0.0, 0.0), (0, 1, 0)),         # hip pitch
        (f"{side}LEG_JOINT3", f"{side}LEG_LINK2", (0.0, 0.0, -THIGH), (0, 1, 0)),      # knee
        (f"{side}LEG_JOINT4", f"{side}LEG_LINK3", (0.0, 0.0, -SHANK), (0, 1, 0)),      # ankle pitch
        (f"{side}LEG_JOINT5", f"{side}LEG_LINK4", (0.0, 0.0, 0.0), (1, 0, 0)),         # ankle roll
    ]
    JOINTS += [(n, p, n.replace("JOINT", "LINK"), o, a) for n, p, o, a in leg]
trunk = [
    ("CHEST_JOINT0", "BODY", (0.0, 0.0, CHEST_Z), (0, 0, 1)),           # chest yaw
    ("CHEST_JOINT1", "CHEST_LINK0", (0.0, 0.0, 0.0), (0, 1, 0)),        # chest pitch
    ("HEAD_JOINT0", "CHEST_LINK1", (0.0, 0.0, NECK_Z), (0, 0, 1)),      # neck yaw
    ("HEAD_JOINT1", "HEAD_LINK0", (0.0, 0.0, 0.0), (0, 1, 0)),          # neck pitch
]
JOINTS += [(n, p, n.replace("JOINT", "LINK"), o, a) for n, p, o, a in trunk]
for side, sign in (("R", -1.0), ("L", 1.0)):
    arm = [
        (f"{side}ARM_JOINT0", "CHEST_LINK1", (0.0, sign * SHOULDER_Y, SHOULDER_Z), (0, 1, 0)),  # shoulder pitch
        (f"{side}ARM_JOINT1", f"{side}ARM_LINK0", (0.0, 0.0, 0.0), (1, 0, 0)),                  # shoulder roll
        (f"{side}ARM_JOINT2", f"{side}ARM_LINK1", (0.0, 0.0, 0.0), (0, 0, 1)),                  # shoulder yaw
        (f"{side}ARM_JOINT3", f"{side}ARM_LINK2", (0.0, 0.0, -UPPER_ARM), (0, 1, 0)),           # elbow
        (f"{side}ARM_JOINT4", f"{side}ARM_LINK3", (0.0, 0.0, -FOREARM), (0, 0, 1)),             # wrist yaw
        (f"{side}ARM_JOINT5", f"{side}ARM_LINK4", (0.0, 0.0, 0.0), (0, 1, 0)),                  # wrist pitch
        (f"{side}ARM_JOINT6", f"{side}ARM_LINK5", (0.0, 0.0, -HAND_TO_GRIPPER), (1, 0, 0)),     # gripper
    ]
    JOINTS += [(n, p, n.replace("JOINT", "LINK"), o, a) for n, p, o, a in arm]

# Fixed frames: soles (contact surfaces), palms, top of the head (height check).
FRAMES = [
    ("r_sole", "RLEG_LINK5", (0.0, 0.0, -SOLE_BELOW_ANKLE)),
    ("l_sole", "LLEG_LINK5", (0.0, 0.0, -SOLE_BELOW_ANKLE)),
    ("r_palm", "RARM_LINK5", (0.0, 0.0, -0.16)),  # below the closed gripper
    ("l_palm", "LARM_LINK5", (0.0, 0.0, -0.16)),
    ("head_top", "HEAD_LINK1", (0.0, 0.0, HEAD_TOP)),
]

# Actuator classes (estimates, see README): effort limit [N m], velocity limit [rad/s].
def effort_velocity(name):
    if "LEG" in name:
        return {"0": (120, 5.0), "1": (150, 5.0), "2": (200, 5.0), "3": (250, 5.0), "4": (200, 5.0), "5": (120, 5.0)}[name[-1]]
    if "CHEST" in name:
        return (150, 4.0)
    if "HEAD" in name:
        return (15, 6.0)
    return {"0": (80, 5.0), "1": (80, 5.0), "2": (50, 6.0), "3": (60, 6.0), "4": (20, 8.0), "5": (20, 8.0), "6": (10, 8.0)}[name[-1]]


def box_inertia(m, size):
    x, y, z = size
    return (m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12)


def fmt(v):
    return " ".join(f"{x:.6g}" for x in v)


def write_urdf():
    mass = sum(m for m, _, _ in LINKS.values())
    assert abs(mass - TOTAL_MASS) < 1e-9, mass
    assert len(JOINTS) == 30
    out = ['<?xml version="1.0"?>',
           "<!-- HRP-2, written by the mcopt project from public facts and estimates.",
           "     Generated by generate_hrp2.py: edit the table there, not this file.",
           "     Sources and estimation methods: README.md in this folder. -->",
           '<robot name="hrp2">']
    for name, (m, size, com) in LINKS.items():
        ixx, iyy, izz = box_inertia(m, size)
        out += [f'  <link name="{name}">', "    <inertial>", f'      <origin xyz="{fmt(com)}" rpy="0 0 0"/>',
                f'      <mass value="{m:g}"/>',
                f'      <inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{iyy:.6g}" iyz="0" izz="{izz:.6g}"/>',
                "    </inertial>", "  </link>"]
    for name, parent, child, origin, axis in JOINTS:
        lo, hi = RANGES[name]
        effort, velocity = effort_velocity(name)
        out += [f'  <joint name="{name}" type="revolute">', f'    <parent link="{parent}"/>',
                f'    <child link="{child}"/>', f'    <origin xyz="{fmt(origin)}" rpy="0 0 0"/>',
                f'    <axis xyz="{fmt(axis)}"/>',
                f'    <limit lower="{lo}" upper="{hi}" effort="{effort}" velocity="{velocity}"/>', "  </joint>"]
    for name, parent, origin in FRAMES:
        out += [f'  <link name="{name}"/>', f'  <joint name="{name}_fixed" type="fixed">',
                f'    <parent link="{parent}"/>', f'    <child link="{name}"/>',
                f'    <origin xyz="{fmt(origin)}" rpy="0 0 0"/>', "  </joint>"]
    out.append("</robot>")
    (HERE / "hrp2.urdf").write_text("\n".join(out) + "\n")


def table():
    rows = ["| quantity | value | source or method |", "|---|---|---|",
            f"| height (zero posture, sole to head top) | {HEIGHT} m | {FACT} |",
            f"| total mass | {TOTAL_MASS} kg | {FACT} (with batteries) |",
            f"| sole below ankle axes | {SOLE_BELOW_ANKLE} m | {FACT} |",
            "| joint names, order and axes | OpenHRP layout | " + FACT + " |",
            "| joint ranges | see hrp2.urdf `<limit>` | " + FACT + " |"]
    for label, value in (("hip lateral offset", HIP_Y), ("thigh (hip pitch → knee)", THIGH),
                         ("shank (knee → ankle)", SHANK), ("waist → chest joints", CHEST_Z),
                         ("chest joints → shoulder axes", SHOULDER_Z), ("shoulder lateral offset", SHOULDER_Y),
                         ("chest joints → neck joints", NECK_Z), ("neck → head top", round(HEAD_TOP, 6)),
                         ("upper arm", UPPER_ARM), ("forearm", FOREARM), ("wrist → gripper axis", HAND_TO_GRIPPER)):
        method = "closes the published height" if label == "neck → head top" else EST_GEOM
        rows.append(f"| {label} | {value} m | {method} |")
    for name, (m, size, com) in LINKS.items():
        rows.append(f"| {name}: mass / box / com | {m} kg / {fmt(size)} m / {fmt(com)} m | {EST_MASS}; inertia: {EST_BOX} |")
    frame_methods = {"r_sole": FACT + " (0.105 m below the ankle)", "l_sole": FACT + " (0.105 m below the ankle)",
                     "r_palm": "estimate: below the closed gripper (hand box 0.12 m + finger 0.04 m)",
                     "l_palm": "estimate: below the closed gripper (hand box 0.12 m + finger 0.04 m)",
                     "head_top": "top of the head box: closes the published height"}
    for name, parent, origin in FRAMES:
        rows.append(f"| frame {name} on {parent} | {fmt(origin)} m | {frame_methods[name]} |")
    rows.append("| effort and velocity limits (URDF defaults) | per joint class | estimate, see actuators.yaml |")
    return "\n".join(rows) + "\n"


README_HEAD = """<!-- Generated by generate_hrp2.py: edit the script, not this file. -->
# HRP-2 model (ours)

No openly licensed HRP-2 description exists (the LAAS and HRP-2-Kai descriptions are
private; a public file of HRP-2 No. 14 inertial parameters declares a closed licence and is
not used). This model is written by the mcopt project from the public facts gathered in
`../shared/docs/hrp2-facts.md` (the robot's documentation and the source report, §1.3) and
from estimates, each labelled below. It is good for method development and benchmarking of
an HRP-2-sized, HRP-2-shaped robot; it is **not** the real robot's identified model.

| file | content |
|---|---|
| `hrp2.urdf` | 30 actuated joints in OpenHRP names and layout, masses, centres of mass, inertias, ranges; generated by `generate_hrp2.py` |
| `actuators.yaml` | gear ratios, torque constants, resistances, rotor inertias, friction, torque and velocity limits |
| `contacts.yaml` | both soles and both hands, friction coefficients |
| `postures.yaml` | `half_sitting`, `zero` |

Frames for contacts and checks: `r_sole`, `l_sole` (0.105 m below the ankle axes), `r_palm`,
`l_palm` (below the closed grippers), `head_top`. Joint axes follow the OpenHRP convention
(x forward, y left, z up at the zero posture): hip yaw z, hip roll x, hip/knee/ankle pitch y,
ankle roll x; chest yaw z, pitch y; neck yaw z, pitch y; shoulder pitch y, roll x, yaw z, elbow
y, wrist yaw z, wrist pitch y, gripper x. Positive knee and elbow signs match the published
ranges (knee bends with positive angles, elbow with negative ones).

## Kinematics and inertia

Inertias are those of solid boxes of the listed size and mass about the box centre
(`I_xx = m (y² + z²)/12` …), axes aligned with the link frame.

"""

README_TAIL = """
## Actuators (`actuators.yaml`)

HRP-2 drives each joint with a brushed DC motor and a harmonic-drive reduction (robot
documentation); which motor, winding and ratio sit at each joint is not public. All actuator
numbers are **estimates** by motor class:

| class | used for | K [N m/A] | R [Ω] | rotor [kg m²] | method |
|---|---|---|---|---|---|
| 150 W (maxon RE 40 size, 24 V winding) | hip roll/pitch, knee, ankles, chest | 0.0302 | 0.299 | 1.34e-5 | catalogue values of the class as recalled by the authors, not checked against a datasheet here |
| 90 W (maxon RE 35 size, 24 V winding) | hip yaw, shoulder pitch/roll, elbow | 0.0261 | 0.583 | 6.96e-6 | as above |
| 20 W (maxon RE 25 size, 24 V winding) | upper-arm yaw, wrists, neck, grippers | 0.0234 | 2.18 | 1.08e-6 | as above |

| quantity | value | method |
|---|---|---|
| gear ratios | 200 (hip/knee/ankle pitch), 160 (other leg, chest, shoulder, elbow), 100 (neck, wrists, grippers) | estimate: harmonic-drive ratios (100–160) with a 2:1 belt stage on the pitch joints that carry the body |
| velocity limits | 838 rad/s / N (4.19, 5.24, 8.38 rad/s) | estimate: 8000 rpm class maximum motor speed over the ratio |
| torque limits | 250 (knee), 200 (hip and ankle pitch), 150 (hip roll, chest), 120 (hip yaw, ankle roll), 80 (shoulder), 60 (elbow), 50 (upper-arm yaw), 20 (wrist), 15 (neck), 10 (gripper) N m | estimate: momentary peak torque of a harmonic drive of the size that fits the link |
| viscous friction (motor side) | 1e-6 to 3e-6 N m s/rad | estimate: no-load current × K over no-load speed, class order of magnitude |
| dry friction (motor side) | 0.003 to 0.008 N m | estimate: class no-load friction torque |
| friction sharpness ν | 100 s/rad | modelling choice (formulation.md §4) |

## Contact surfaces (`contacts.yaml`)

| surface | rectangle [m] | μ | method |
|---|---|---|---|
| soles | x ∈ [−0.095, 0.135], y ∈ [−0.065, 0.065] about the sole frame | 0.7 | estimate: foot of 0.23 × 0.13 m with the ankle 2 cm behind its centre, from the robot's proportions; JVRC-1's sole (0.20 × 0.08 m) for comparison; μ: rubber sole on floor, estimate |
| hands | x ∈ [−0.04, 0.04], y ∈ [−0.025, 0.025] | 0.5 | estimate: closed-gripper knuckles on a table |

## Postures (`postures.yaml`)

`half_sitting`: the standard HRP-2 rest posture used by the AIST/LAAS control software (hip
−26°, knee 50°, ankle −24°; shoulders 15°, ±10°, elbows −30°, grippers 10°), published in
the walking-control literature on HRP-2. `zero`: all joints at zero (legs straight, arms down),
the posture whose height is 1.54 m.

## Checks (`tests/robots/test_hrp2_model.cpp`)

30 actuated joints, 58 ± 0.5 kg, 1.54 ± 0.02 m from sole to head top at the zero posture, and in
half-sitting — rooted at either sole with both soles flat on the ground, the whole weight on the
reference leg — every static torque within its limit and the centre of mass inside the support
polygon by more than 2 cm.
"""


if __name__ == "__main__":
    write_urdf()
    (HERE / "README.md").write_text(README_HEAD + table() + README_TAIL)
    print("wrote hrp2.urdf and README.md")
