# SKYBAKE_WITH_MPI: AUTO (when find_package(MPI) finds Open MPI), ON or OFF.
# Sets SKYBAKE_HAS_MPI. The MPI code is the one module skybake::distributed
# (src/distributed/); without MPI that module is a stub whose entry points
# throw one clear error (skybake/distributed.h).
set(SKYBAKE_WITH_MPI AUTO CACHE STRING "Distributed bakes with MPI: AUTO (when Open MPI is found), ON or OFF")
set_property(CACHE SKYBAKE_WITH_MPI PROPERTY STRINGS AUTO ON OFF)
set(SKYBAKE_HAS_MPI OFF)
set(SKYBAKE_MPIEXEC "")
if(NOT SKYBAKE_WITH_MPI STREQUAL "OFF")
  if(SKYBAKE_WITH_MPI STREQUAL "ON")
    find_package(MPI REQUIRED COMPONENTS C)
  else()
    find_package(MPI QUIET COMPONENTS C)
  endif()
  if(MPI_C_FOUND)
    # Open MPI's mpi.h defines OPEN_MPI.
    set(skybake_open_mpi OFF)
    foreach(dir IN LISTS MPI_C_INCLUDE_DIRS MPI_C_HEADER_DIR)
      if(EXISTS "${dir}/mpi.h")
        file(STRINGS "${dir}/mpi.h" skybake_mpi_define REGEX "define[ \t]+OPEN_MPI[ \t]+1")
        if(skybake_mpi_define)
          set(skybake_open_mpi ON)
        endif()
      endif()
    endforeach()
    if(SKYBAKE_WITH_MPI STREQUAL "ON" OR skybake_open_mpi)
      set(SKYBAKE_HAS_MPI ON)
      set(SKYBAKE_MPIEXEC "${MPIEXEC_EXECUTABLE}")
    else()
      message(STATUS "skybake: MPI found but not Open MPI (${MPI_C_INCLUDE_DIRS}); "
                     "distributed bakes off (-DSKYBAKE_WITH_MPI=ON to use it anyway)")
    endif()
  endif()
endif()
