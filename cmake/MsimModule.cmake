# msim_module(NAME [DIR path] [PARTS folder...] DEPS targets...): library msim_NAME from
# src/msim/<path>/*.cpp and src/msim/<path>/<folder>/*.cpp for each of PARTS (path defaults to
# NAME; parts are subfolders that belong to the same library, unlike a nested module such as
# scene/schema). Header-only modules become INTERFACE libraries.
function(msim_module name)
  cmake_parse_arguments(M "" "DIR" "PARTS;DEPS" ${ARGN})
  if(NOT M_DIR)
    set(M_DIR ${name})
  endif()
  file(GLOB sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/msim/${M_DIR}/*.cpp)
  foreach(part ${M_PARTS})
    file(GLOB part_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/msim/${M_DIR}/${part}/*.cpp)
    list(APPEND sources ${part_sources})
  endforeach()
  if(sources)
    add_library(msim_${name} STATIC ${sources})
    target_include_directories(msim_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src ${PROJECT_BINARY_DIR}/generated)
    target_link_libraries(msim_${name} PUBLIC ${M_DEPS})
  else()
    add_library(msim_${name} INTERFACE)
    target_include_directories(msim_${name} INTERFACE ${PROJECT_SOURCE_DIR}/src ${PROJECT_BINARY_DIR}/generated)
    target_link_libraries(msim_${name} INTERFACE ${M_DEPS})
  endif()
endfunction()
