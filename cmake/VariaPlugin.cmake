# varia_add_plugin(<name> SOURCES <files...> [OUTPUT_DIRECTORY <dir>] [NO_INSTALL])
# Builds a varia plugin: a MODULE library with hidden symbols (only the VARIA_PLUGIN exports are
# visible), linked against the plugin SDK, written where the host finds it (VARIA_PLUGIN_OUTPUT_DIR
# unless OUTPUT_DIRECTORY is given) and installed to VARIA_PLUGIN_INSTALL_DIR when that is set
# (unless NO_INSTALL). The host loads plugins only from files and directories that group and
# others cannot write, so the file and its directory lose those permission bits after each build,
# whatever the umask.
function(varia_add_plugin name)
  cmake_parse_arguments(ARG "NO_INSTALL" "OUTPUT_DIRECTORY" "SOURCES" ${ARGN})
  if(NOT ARG_OUTPUT_DIRECTORY)
    set(ARG_OUTPUT_DIRECTORY ${VARIA_PLUGIN_OUTPUT_DIR})
  endif()
  add_library(${name} MODULE ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE varia::sdk)
  set_target_properties(${name} PROPERTIES
    PREFIX ""
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  add_custom_command(TARGET ${name} POST_BUILD
    COMMAND chmod go-w $<TARGET_FILE:${name}> $<TARGET_FILE_DIR:${name}>
    VERBATIM)
  if(DEFINED VARIA_PLUGIN_INSTALL_DIR AND NOT ARG_NO_INSTALL)
    install(TARGETS ${name} LIBRARY DESTINATION ${VARIA_PLUGIN_INSTALL_DIR})
    set_property(GLOBAL APPEND PROPERTY VARIA_PLUGINS ${name})
  endif()
endfunction()
