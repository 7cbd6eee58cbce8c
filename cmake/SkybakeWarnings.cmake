function(skybake_set_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wno-unused-parameter>
    # GLM's defaulted constructors carry __host__ __device__; nvcc warns and ignores.
    $<$<COMPILE_LANGUAGE:CUDA>:-diag-suppress=20012 --expt-relaxed-constexpr -Xcompiler=-Wall>)
endfunction()
