# SPDX-License-Identifier: BSD-3-Clause
cmake_minimum_required(VERSION 3.20)
# Third-party libraries stay behind the targets that link them privately (style.md §9,
# issue 19): no public header of core, inner_qp, sensitivity or outer_nlp names yaml-cpp,
# urdfdom, Ipopt, NLopt or SuiteSparse, their headers or their types — except the two
# YAML-reading headers that say so and whose includers link yaml-cpp themselves.
#   cmake -DSOURCE_DIR=... -P header_boundaries.cmake
set(allowed_yaml core/yaml_fields.hpp outer_nlp/scenario_yaml.hpp)
set(patterns
  "yaml-cpp|YAML::" "urdf_|urdf::|console_bridge" "Ip[A-Z][A-Za-z]*\\.hpp|Ipopt::|coin/" "nlopt" "klu\\.h|umfpack|cholmod|klu_")
set(failures "")
set(checked 0)
foreach(module core inner_qp sensitivity outer_nlp)
  file(GLOB headers RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/${module}/*.hpp)
  foreach(header ${headers})
    math(EXPR checked "${checked} + 1")
    file(STRINGS ${SOURCE_DIR}/${header} lines)
    set(number 0)
    foreach(line IN LISTS lines)
      math(EXPR number "${number} + 1")
      # Comments may name a library; code may not.
      string(REGEX REPLACE "//.*$" "" code "${line}")
      foreach(pattern ${patterns})
        if(code MATCHES "${pattern}")
          if(pattern STREQUAL "yaml-cpp|YAML::" AND header IN_LIST allowed_yaml)
            continue()
          endif()
          string(APPEND failures "${header}:${number}: ${line}\n")
        endif()
      endforeach()
    endforeach()
  endforeach()
endforeach()
if(checked LESS 40)
  message(FATAL_ERROR "header boundaries: only ${checked} headers found under ${SOURCE_DIR}")
endif()
if(failures)
  message(FATAL_ERROR "third-party names in public headers:\n${failures}")
endif()
message(STATUS "header boundaries: ${checked} headers clean")
