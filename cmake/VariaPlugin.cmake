# varia_add_plugin(<name> SOURCES <files...>)
# Builds a varia plugin: a MODULE library with hidden symbols (only the VARIA_PLUGIN exports are
# visible), linked against the plugin SDK, written where the host finds it.
function(varia_add_plugin name)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  add_library(${name} MODULE ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE varia::sdk)
  set_target_properties(${name} PROPERTIES
    PREFIX ""
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LIBRARY_OUTPUT_DIRECTORY ${VARIA_PLUGIN_OUTPUT_DIR})
  if(DEFINED VARIA_PLUGIN_INSTALL_DIR)
    install(TARGETS ${name} LIBRARY DESTINATION ${VARIA_PLUGIN_INSTALL_DIR})
  endif()
  set_property(GLOBAL APPEND PROPERTY VARIA_PLUGINS ${name})
endfunction()
