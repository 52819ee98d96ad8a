# Flags of the portable core, the same on host and target so both compute the same
# float32 numbers: no contraction into fused multiply-add, no errno from sqrtf (so it
# is one instruction, never a libm call).
set(PMSTEP_CORE_C_FLAGS
    -Wall -Wextra -Wpedantic -Wconversion -Wshadow -Wdouble-promotion -Werror
    -ffp-contract=off -fno-math-errno)

function(pmstep_strict_c target)
  set_target_properties(${target} PROPERTIES C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE ${PMSTEP_CORE_C_FLAGS})
endfunction()
