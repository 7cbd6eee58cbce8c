# SKYBAKE_WITH_CUDA = AUTO | ON | OFF.
# AUTO turns CUDA on when nvcc is found (PATH, CUDACXX or /usr/local/cuda).
# CUDA targets are compiled whether or not a GPU is present; GPU tests skip at
# run time when no device exists.
set(SKYBAKE_HAS_CUDA OFF)
if(NOT SKYBAKE_WITH_CUDA STREQUAL "OFF")
  if(NOT CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX} AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      # Hopper (H100/H200) as SASS, plus PTX so that newer GPUs can JIT it.
      set(CMAKE_CUDA_ARCHITECTURES 90-real 90-virtual)
    endif()
    enable_language(CUDA)
    # CMake 3.25 does not know nvcc's C++20 dialect flag (nvcc >= 12 has it).
    if(NOT CMAKE_CUDA20_STANDARD_COMPILE_OPTION)
      set(CMAKE_CUDA20_STANDARD_COMPILE_OPTION "-std=c++20")
      set(CMAKE_CUDA20_EXTENSION_COMPILE_OPTION "-std=c++20")
    endif()
    set(CMAKE_CUDA_STANDARD 20)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    find_package(CUDAToolkit REQUIRED)
    set(SKYBAKE_HAS_CUDA ON)
  elseif(SKYBAKE_WITH_CUDA STREQUAL "ON")
    message(FATAL_ERROR "SKYBAKE_WITH_CUDA=ON but no CUDA compiler was found. Install the CUDA toolkit or set CUDACXX.")
  endif()
endif()
