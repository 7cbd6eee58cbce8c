# skybake_add_tests(NAME FILES f... [LIBS target...])
#
# Builds one GoogleTest executable per label from the given sources:
#   *_slow_test.cpp   -> label "slow"
#   *_gpu_test.cpp/cu -> label "gpu"  (tests call GTEST_SKIP() without a device)
#   *_io_test.cpp     -> label "io" (unit tests of file I/O; also run under the
#                        sanitizer build). `ctest -L 'unit|io'` runs both.
#   *_gl_test.cpp     -> label "gl" (the OpenGL planet renderer and its mesh;
#                        headless EGL, passes on Mesa llvmpipe)
#   other *_test.cpp  -> label "unit"
# Test names are prefixed with NAME.
find_package(GTest REQUIRED)
include(GoogleTest)

# Every test runs without the on-disk table cache (sky_table_cache_dir()): it
# neither reads nor fills the user's cache, and always computes fresh tables.
# The cache's own tests point SKYBAKE_CACHE_DIR at a folder of their own.
set(SKYBAKE_TEST_ENVIRONMENT "SKYBAKE_CACHE_DIR=off")

function(skybake_add_tests name)
  cmake_parse_arguments(T "" "" "FILES;LIBS" ${ARGN})
  set(groups unit io slow gpu gl)
  foreach(g IN LISTS groups)
    set(files_${g} "")
  endforeach()
  foreach(f IN LISTS T_FILES)
    if(f MATCHES "_slow_test\\.(cpp|cu)$")
      list(APPEND files_slow ${f})
    elseif(f MATCHES "_gpu_test\\.(cpp|cu)$")
      if(f MATCHES "\\.cu$" AND NOT SKYBAKE_HAS_CUDA)
        continue()
      endif()
      list(APPEND files_gpu ${f})
    elseif(f MATCHES "_io_test\\.(cpp|cu)$")
      list(APPEND files_io ${f})
    elseif(f MATCHES "_gl_test\\.cpp$")
      list(APPEND files_gl ${f})
    else()
      list(APPEND files_unit ${f})
    endif()
  endforeach()
  foreach(g IN LISTS groups)
    if(NOT files_${g})
      continue()
    endif()
    if(g STREQUAL "unit")
      set(exe ${name}_tests)
    else()
      set(exe ${name}_${g}_tests)
    endif()
    add_executable(${exe} ${files_${g}})
    target_link_libraries(${exe} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main fmt::fmt)
    target_include_directories(${exe} PRIVATE ${PROJECT_SOURCE_DIR}/src ${PROJECT_SOURCE_DIR}/tests)
    target_compile_definitions(${exe} PRIVATE
      SKYBAKE_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      SKYBAKE_ASSIMP_MODELS="/usr/share/assimp/models"
      SKYBAKE_CLI_PATH="$<TARGET_FILE:skybake_cli>")
    skybake_set_warnings(${exe})
    if(g STREQUAL "io")
      set_property(GLOBAL APPEND PROPERTY SKYBAKE_IO_TEST_TARGETS ${exe})
    endif()
    gtest_discover_tests(${exe} TEST_PREFIX "${name}." DISCOVERY_MODE PRE_TEST
      PROPERTIES LABELS ${g} TIMEOUT 600 ENVIRONMENT "${SKYBAKE_TEST_ENVIRONMENT}")
  endforeach()
endfunction()

# Tests beside the sources of a module: src/NAME/**/*_test.cpp
function(skybake_add_module_tests name)
  cmake_parse_arguments(T "" "" "LIBS" ${ARGN})
  file(GLOB_RECURSE files CONFIGURE_DEPENDS
    ${PROJECT_SOURCE_DIR}/src/${name}/*_test.cpp ${PROJECT_SOURCE_DIR}/src/${name}/*_test.cu)
  if(files)
    skybake_add_tests(${name} FILES ${files} LIBS skybake_${name} ${T_LIBS})
  endif()
endfunction()
