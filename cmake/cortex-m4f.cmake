# Cortex-M4 with single-precision FPU (STM32G4, MPS2-AN386).
set(PMSTEP_CPU_FLAGS -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard)
add_compile_options(${PMSTEP_CPU_FLAGS})
add_link_options(${PMSTEP_CPU_FLAGS})
