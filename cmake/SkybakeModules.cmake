# skybake_add_module(NAME [DEPENDS mod...] [LIBS target...] [PUBLIC_LIBS target...])
#
# One static library per folder src/NAME, target skybake_NAME (alias
# skybake::NAME). Sources are src/NAME/*.cpp, plus src/NAME/*.cu when the
# build has CUDA. Files ending in _test.cpp / _test.cu are test sources and are
# picked up by skybake_add_tests() instead.
set(SKYBAKE_MODULES "" CACHE INTERNAL "")

function(skybake_add_module name)
  cmake_parse_arguments(M "" "" "DEPENDS;LIBS;PUBLIC_LIBS" ${ARGN})
  set(dir ${PROJECT_SOURCE_DIR}/src/${name})
  file(GLOB_RECURSE cpp CONFIGURE_DEPENDS ${dir}/*.cpp)
  set(cu "")
  if(SKYBAKE_HAS_CUDA)
    file(GLOB_RECURSE cu CONFIGURE_DEPENDS ${dir}/*.cu)
  endif()
  set(sources ${cpp} ${cu})
  list(FILTER sources EXCLUDE REGEX "_test\\.(cpp|cu)$")
  if(NOT sources)
    return() # module not written yet
  endif()
  set(target skybake_${name})
  add_library(${target} STATIC ${sources})
  add_library(skybake::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(${target}
    PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
           $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>
           $<INSTALL_INTERFACE:include>
    PRIVATE ${PROJECT_SOURCE_DIR}/src)
  foreach(dep IN LISTS M_DEPENDS)
    target_link_libraries(${target} PUBLIC skybake_${dep})
  endforeach()
  target_link_libraries(${target} PRIVATE ${M_LIBS} PUBLIC ${M_PUBLIC_LIBS})
  target_compile_features(${target} PUBLIC cxx_std_20) # the public headers are C++20
  if(SKYBAKE_HAS_CUDA)
    target_compile_definitions(${target} PUBLIC $<BUILD_INTERFACE:SKYBAKE_HAS_CUDA=1>)
    if(cu)
      target_link_libraries(${target} PUBLIC CUDA::cudart_static)
    endif()
  endif()
  skybake_set_warnings(${target})
  set(SKYBAKE_MODULES ${SKYBAKE_MODULES} ${name} CACHE INTERNAL "")
endfunction()
