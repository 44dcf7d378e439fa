# SPDX-License-Identifier: BSD-3-Clause
# SuiteSparse as one imported target, mcopt_deps::SuiteSparse: the libraries mcopt::sensitivity
# uses (KLU, UMFPACK and what they need). Debian 12's SuiteSparse 5.12 ships no CMake package,
# so they are found one by one — by the build, and again by mcoptConfig.cmake on the side of a
# project that links mcopt::sensitivity.
if(NOT TARGET mcopt_deps::SuiteSparse)
  set(_mcopt_suitesparse_libraries)
  foreach(_mcopt_library klu umfpack btf amd colamd cholmod suitesparseconfig)
    find_library(MCOPT_SUITESPARSE_${_mcopt_library} NAMES ${_mcopt_library})
    if(NOT MCOPT_SUITESPARSE_${_mcopt_library})
      message(FATAL_ERROR "mcopt: SuiteSparse's ${_mcopt_library} library not found (Debian: libsuitesparse-dev)")
    endif()
    list(APPEND _mcopt_suitesparse_libraries ${MCOPT_SUITESPARSE_${_mcopt_library}})
  endforeach()
  find_path(MCOPT_SUITESPARSE_INCLUDE klu.h PATH_SUFFIXES suitesparse)
  if(NOT MCOPT_SUITESPARSE_INCLUDE)
    message(FATAL_ERROR "mcopt: SuiteSparse's klu.h not found (Debian: libsuitesparse-dev)")
  endif()
  add_library(mcopt_deps::SuiteSparse INTERFACE IMPORTED GLOBAL)
  set_target_properties(mcopt_deps::SuiteSparse PROPERTIES
    INTERFACE_LINK_LIBRARIES "${_mcopt_suitesparse_libraries}"
    INTERFACE_INCLUDE_DIRECTORIES "${MCOPT_SUITESPARSE_INCLUDE}")
endif()
