# Debian 12 ships SuiteSparse 5.12 without CMake package files; this finds the
# CHOLMOD library and its dependencies and offers them as SuiteSparse::CHOLMOD.
# CHOLMOD's BLAS is whatever libblas.so.3 resolves to: install libopenblas-dev so
# the Debian alternatives point it at OpenBLAS (4-8x faster than reference BLAS).

find_path(SuiteSparse_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
foreach(lib cholmod amd camd colamd ccolamd suitesparseconfig)
  find_library(SuiteSparse_${lib}_LIBRARY NAMES ${lib})
  list(APPEND _suitesparse_required SuiteSparse_${lib}_LIBRARY)
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparse
  REQUIRED_VARS SuiteSparse_INCLUDE_DIR ${_suitesparse_required})

if(SuiteSparse_FOUND AND NOT TARGET SuiteSparse::CHOLMOD)
  add_library(SuiteSparse::CHOLMOD INTERFACE IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${SuiteSparse_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES
      "${SuiteSparse_cholmod_LIBRARY};${SuiteSparse_amd_LIBRARY};${SuiteSparse_camd_LIBRARY};${SuiteSparse_colamd_LIBRARY};${SuiteSparse_ccolamd_LIBRARY};${SuiteSparse_suitesparseconfig_LIBRARY}")
endif()
