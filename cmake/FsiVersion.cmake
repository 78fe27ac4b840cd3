# fsi_version: an interface target giving executables <fsi/common/version.hpp>, which holds
# the project version (project() above), the git short hash and the build type. The header
# is regenerated at every build by FsiVersionHeader.cmake but rewritten only when its
# content changes, so a new commit recompiles only the few mains that include it.
set(FSI_VERSION_HEADER ${CMAKE_BINARY_DIR}/generated/fsi/common/version.hpp)
if(CMAKE_CONFIGURATION_TYPES)
  set(_fsi_build_type "$<CONFIG>")
else()
  set(_fsi_build_type "${CMAKE_BUILD_TYPE}")
endif()
add_custom_target(fsi_version_header
  COMMAND ${CMAKE_COMMAND} -DOUT=${FSI_VERSION_HEADER} -DSOURCE_DIR=${CMAKE_SOURCE_DIR}
          -DVERSION=${PROJECT_VERSION} -DBUILD_TYPE=${_fsi_build_type}
          -P ${CMAKE_CURRENT_LIST_DIR}/FsiVersionHeader.cmake
  BYPRODUCTS ${FSI_VERSION_HEADER}
  COMMENT "version header (git hash)"
  VERBATIM)
add_library(fsi_version INTERFACE)
target_include_directories(fsi_version INTERFACE ${CMAKE_BINARY_DIR}/generated)
add_dependencies(fsi_version fsi_version_header)
