// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Sizes on the per-sample hot path (dynamics, derivatives, kinematics) are debug assertions:
// a check there would cost a noticeable share of a small robot's Newton–Euler pass, and every
// caller inside mcopt sizes its arguments from the model once. Debug builds abort with the
// message (tests/core/test_debug_checks.cpp); entry points that start an evaluation from
// outside — evaluators, solvers, the command line — check sizes with InputError.
#include <cassert>

#define MCOPT_HOT_PATH_CHECK(condition, message) assert((condition) && (message))
