# marionette_runtime_library(NAME SOURCES... DEPENDS targets...): one runtime
# concern as a static library (or an INTERFACE one when it has no sources).
# Includes are written from the project root ("runtime/anim/clip.hpp").
function(marionette_runtime_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  if(ARG_SOURCES)
    add_library(${name} STATIC ${ARG_SOURCES})
    target_include_directories(${name} PUBLIC "${PROJECT_SOURCE_DIR}")
    target_link_libraries(${name} PUBLIC ${ARG_DEPENDS} marionette_options glm::glm
                                  PRIVATE ${ARG_PRIVATE_DEPENDS})
  else()
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE "${PROJECT_SOURCE_DIR}")
    target_link_libraries(${name} INTERFACE ${ARG_DEPENDS} marionette_options glm::glm)
  endif()
endfunction()
