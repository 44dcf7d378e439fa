# SPDX-License-Identifier: BSD-3-Clause
# The fuzz targets (tests/fuzz/fuzz_<name>.cpp), for the libFuzzer build and for the test
# suite's runs of their corpora and regression inputs.
set(MCOPT_FUZZ_TARGETS scenario robot_files dynamics_states inner_problems)
