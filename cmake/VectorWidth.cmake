# outburst_vector_bytes(<var>): the width in bytes of the vectors GCC's
# vectoriser picks for doubles under the build's flags (16: two doubles; 32:
# four), or empty where the compiler does not say (not GCC). The tuning, not
# the instruction set, decides it: -march=native on a first-generation Zen
# has AVX2 and prefers 16, as does the default x86-64; Haswell and later,
# Zen 2 and later and the AVX-512 processors prefer 32. No macro tells the
# source, so the build asks the vectoriser.
function(outburst_vector_bytes var)
  set(${var} "" PARENT_SCOPE)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    return()
  endif()
  # The Release flags: the caller asks for Release builds only.
  separate_arguments(flags UNIX_COMMAND "${CMAKE_CXX_FLAGS} ${CMAKE_CXX_FLAGS_RELEASE}")
  if(OUTBURST_NATIVE)
    list(APPEND flags -march=native)
  endif()
  execute_process(
    COMMAND ${CMAKE_CXX_COMPILER} ${flags} -fopt-info-vec-optimized -S -o ${CMAKE_BINARY_DIR}/vector_width_probe.s
            ${PROJECT_SOURCE_DIR}/cmake/vector_width_probe.cpp
    RESULT_VARIABLE failed OUTPUT_VARIABLE report ERROR_VARIABLE report)
  # The first report is the loop's main body (an epilogue may follow, narrower).
  if(NOT failed AND report MATCHES "vectorized using ([0-9]+) byte vectors")
    set(${var} ${CMAKE_MATCH_1} PARENT_SCOPE)
  endif()
endfunction()
