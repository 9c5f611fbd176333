# Compiler settings shared by every ARBCI target (applied through arbci_options).
add_library(arbci_options INTERFACE)
target_compile_options(arbci_options INTERFACE -Wall -Wextra -Werror)
target_compile_definitions(arbci_options INTERFACE
  ARBCI_VERSION="${PROJECT_VERSION}"
  ARBCI_ASSETS_DIR="${CMAKE_SOURCE_DIR}/assets")
if(ARBCI_SANITIZE_THREAD)
  target_compile_options(arbci_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(arbci_options INTERFACE -fsanitize=thread)
endif()
if(ARBCI_SANITIZE)
  target_compile_options(arbci_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                 -fno-sanitize-recover=undefined)
  target_link_options(arbci_options INTERFACE -fsanitize=address,undefined)
endif()

# arbci_precompile(TARGET HEADERS...): the third-party headers a target's sources share, parsed
# once for the target rather than once a file (the build profile: CLI11 costs ~8 s a file,
# nlohmann/json ~1.8 s, Eigen, OpenCV and GoogleTest ~1.2 s each). ARBCI_PCH=OFF builds without.
option(ARBCI_PCH "Precompile the heavy third-party headers" ON)
function(arbci_precompile target)
  if(ARBCI_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()
# arbci_precompile_reuse(TARGET FROM): TARGET's few files use FROM's precompiled header instead of
# parsing the same headers again (an executable's main beside the library it calls).
function(arbci_precompile_reuse target from)
  if(ARBCI_PCH)
    target_precompile_headers(${target} REUSE_FROM ${from})
  endif()
endfunction()

# arbci_module(NAME SOURCES...): a module library with its public headers in NAME/include.
function(arbci_module name)
  add_library(${name} STATIC ${ARGN})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(${name} PRIVATE arbci_options)
endfunction()

# arbci_embed_assets(TARGET FILES...): compiles the named files under assets/ into TARGET,
# readable through arbci::assets::embedded("shaders/flat.vert").
function(arbci_embed_assets target)
  set(output "${CMAKE_CURRENT_BINARY_DIR}/${target}_embedded_assets.cpp")
  set(inputs "")
  foreach(path IN LISTS ARGN)
    list(APPEND inputs "${ARBCI_ASSETS_DIR}/${path}")
  endforeach()
  string(REPLACE ";" "\\;" files "${ARGN}")
  add_custom_command(OUTPUT "${output}"
    COMMAND ${CMAKE_COMMAND} -DBASE=${ARBCI_ASSETS_DIR} "-DFILES=${files}" -DOUTPUT=${output}
            -P ${CMAKE_SOURCE_DIR}/cmake/EmbedAssets.cmake
    DEPENDS ${inputs} ${CMAKE_SOURCE_DIR}/cmake/EmbedAssets.cmake
    COMMENT "Embedding assets into ${target}")
  target_sources(${target} PRIVATE "${output}")
endfunction()
