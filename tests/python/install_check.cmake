# SPDX-License-Identifier: BSD-3-Clause
# Installs the python component into a fresh prefix and imports the module from there alone
# (run by CTest: cmake -DBUILD_DIR= -DPREFIX= -DPYTHON= -DMODULE_DIR= -DSOURCE_DIR= -P this).
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --component python --prefix "${PREFIX}"
                RESULT_VARIABLE installed)
if(NOT installed EQUAL 0)
  message(FATAL_ERROR "cmake --install --component python failed")
endif()
set(ENV{PYTHONPATH} "${PREFIX}/${MODULE_DIR}")
execute_process(
  COMMAND "${PYTHON}" -c "import mcopt, os; assert os.path.dirname(mcopt.__file__) == os.environ['PYTHONPATH'], mcopt.__file__; r = mcopt.Robot('${SOURCE_DIR}/robots/hrp2/hrp2.urdf'); print(mcopt.__file__, r)"
  RESULT_VARIABLE imported OUTPUT_VARIABLE said ERROR_VARIABLE errors)
if(NOT imported EQUAL 0)
  message(FATAL_ERROR "the installed module does not import: ${errors}")
endif()
message(STATUS "installed and imported: ${said}")
