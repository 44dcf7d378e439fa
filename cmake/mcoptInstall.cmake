# SPDX-License-Identifier: BSD-3-Clause
# What `cmake --install` puts under the prefix (docs/getting-started/install.md), the exported
# CMake package and pkg-config file, and the Debian package `cpack -G DEB` makes from it.
#   bin/mcopt                        the command; it finds its data in share/mcopt (apps/data_paths.hpp)
#   lib/libmcopt_*.a                 mcopt::core, inner_qp, sensitivity, outer_nlp, study
#   include/mcopt/<library>/*.hpp    the public headers (below: each library's private ones are left out)
#   lib/cmake/mcopt/                 find_package(mcopt 0.1): targets, dependencies, version
#   lib/pkgconfig/mcopt-core.pc      the core library for pkg-config
#   share/mcopt/                     robots/hrp2, scenarios, the plotting scripts, the replay page's template
#   share/doc/mcopt/                 README, licence (copyright), the command-line reference
#   the Python module                python/CMakeLists.txt
set(MCOPT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/mcopt)
set(MCOPT_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/mcopt)

set(mcopt_installed_libraries core inner_qp sensitivity outer_nlp study)
foreach(library ${mcopt_installed_libraries})
  set_target_properties(mcopt_${library} PROPERTIES EXPORT_NAME ${library})
endforeach()
install(TARGETS mcopt_core mcopt_inner_qp mcopt_sensitivity mcopt_outer_nlp mcopt_study EXPORT mcoptTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development)
install(TARGETS mcopt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)

# Public headers: every header of an installed library but those below, which are the
# libraries' own machinery (what we do not promise to keep). A test compiles every installed
# header alone against the prefix (tests/install/), so a public header that includes a private
# one fails there.
set(mcopt_private_headers
  core/hot_path_checks.hpp core/no_malloc_scope.hpp core/yaml_fields.hpp core/text_encoding.hpp core/path_status.hpp
  core/atomic_file.hpp
  inner_qp/answer_polishing.hpp inner_qp/inner_nlp.hpp inner_qp/nlopt_problem.hpp inner_qp/dual_active_set_qp.hpp
  sensitivity/sparse_kkt_factor.hpp
  outer_nlp/motion_workspace.hpp outer_nlp/contact_force_formulation.hpp outer_nlp/scenario_yaml.hpp outer_nlp/smooth_maximum.hpp
  study/child_process.hpp study/scenario_tree.hpp)
foreach(library ${mcopt_installed_libraries})
  file(GLOB headers RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${library}/*.hpp)
  list(REMOVE_ITEM headers ${mcopt_private_headers})
  install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mcopt/${library} COMPONENT development)
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/generated/core/version.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mcopt/core
        COMPONENT development)

install(EXPORT mcoptTargets NAMESPACE mcopt:: DESTINATION ${MCOPT_INSTALL_CMAKEDIR} COMPONENT development)
configure_package_config_file(cmake/mcoptConfig.cmake.in ${PROJECT_BINARY_DIR}/mcoptConfig.cmake
                              INSTALL_DESTINATION ${MCOPT_INSTALL_CMAKEDIR} PATH_VARS MCOPT_INSTALL_DATADIR)
# 0.x: a minor version may change the API, so only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/mcoptConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/mcoptConfig.cmake ${PROJECT_BINARY_DIR}/mcoptConfigVersion.cmake
              cmake/mcoptSuiteSparse.cmake
        DESTINATION ${MCOPT_INSTALL_CMAKEDIR} COMPONENT development)

# pkg-config: the core library (rooted dynamics, splines, energy), static, with what it links.
# Relocatable: the prefix is found from the file's own folder (the .deb installs under /usr).
file(RELATIVE_PATH MCOPT_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(cmake/mcopt-core.pc.in ${PROJECT_BINARY_DIR}/mcopt-core.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/mcopt-core.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT development)

install(DIRECTORY robots/hrp2 DESTINATION ${MCOPT_INSTALL_DATADIR}/robots COMPONENT runtime)
install(DIRECTORY scenarios/ DESTINATION ${MCOPT_INSTALL_DATADIR}/scenarios COMPONENT runtime)
install(FILES scripts/plot_result.py scripts/plot_study.py DESTINATION ${MCOPT_INSTALL_DATADIR}/scripts COMPONENT runtime)
install(FILES apps/replay/viewer.html apps/replay/viewer.js DESTINATION ${MCOPT_INSTALL_DATADIR}/replay COMPONENT runtime)
install(FILES README.md docs/reference/cli.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME copyright COMPONENT runtime)

# The Debian package: `cpack -G DEB` in a build folder → mcopt_<version>_amd64.deb, installing
# under /usr. Shared-library dependencies come from dpkg-shlibdeps; the rest are declared here.
# The -dev packages are what find_package(mcopt) finds again on a consumer's side: recommended
# (apt installs them by default), not needed to run the command or import the module; so is
# OpenBLAS, which makes Ipopt's factorisations about twice as fast as the reference BLAS.
set(CPACK_PACKAGE_NAME mcopt)
set(CPACK_PACKAGE_VENDOR "mcopt developers")
set(CPACK_PACKAGE_CONTACT "mcopt developers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "whole-body motion optimisation for humanoid robots in multi-contact")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
# The DEB generator installs with DESTDIR and CMAKE_INSTALL_PREFIX=/usr, which the Python
# module's destination reads (python/CMakeLists.txt).
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# `mcopt plot` runs python3 with matplotlib; `mcopt replay` inlines libjs-three. The module is
# built for this Python (its ABI tag): python3 of the same minor version, and numpy.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3, python3-matplotlib, libjs-three")
if(MCOPT_BUILD_PYTHON)
  math(EXPR mcopt_next_python_minor "${Python3_VERSION_MINOR} + 1")
  set(CPACK_DEBIAN_PACKAGE_DEPENDS
      "python3 (>= 3.${Python3_VERSION_MINOR}), python3 (<< 3.${mcopt_next_python_minor}), python3-numpy, python3-matplotlib, libjs-three")
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS
    "libopenblas0-serial, cmake, pkg-config, libeigen3-dev, coinor-libipopt-dev, libnlopt-cxx-dev, libsuitesparse-dev, liburdfdom-dev, libyaml-cpp-dev, nlohmann-json3-dev")
set(CPACK_GENERATOR DEB)
include(CPack)
