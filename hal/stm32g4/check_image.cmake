# Checks the STM32G431 image the build produced: .elf, .bin and .map exist; the vector
# table at the start of the .bin holds the initial stack pointer (top of the 32 KiB
# SRAM), the reset handler, the NMI handler (the flash's ECC errors of the stored
# configuration), and the ADC1_2 (IRQ 18) and TIM1_BRK (IRQ 24) handlers, each with the
# Thumb bit; flash and RAM use fit the part; the image ends below 0x0801F000, the stored
# configuration's two pages (62, 63), and no symbol lies in them. Prints the size.
# Usage: cmake -DIMAGE_DIR= -DNM= -DSIZE= -P check_image.cmake
cmake_minimum_required(VERSION 3.20)
foreach(var IMAGE_DIR NM SIZE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_image.cmake: -D${var}= missing")
  endif()
endforeach()
set(elf ${IMAGE_DIR}/pmstep-stm32g431.elf)
foreach(f ${elf} ${IMAGE_DIR}/pmstep-stm32g431.bin ${IMAGE_DIR}/pmstep-stm32g431.map)
  if(NOT EXISTS ${f})
    message(FATAL_ERROR "missing ${f}")
  endif()
endforeach()

# Little-endian word @index of the .bin
function(vector_word index out)
  math(EXPR offset "${index} * 4")
  file(READ ${IMAGE_DIR}/pmstep-stm32g431.bin hex OFFSET ${offset} LIMIT 4 HEX)
  string(SUBSTRING ${hex} 0 2 b0)
  string(SUBSTRING ${hex} 2 2 b1)
  string(SUBSTRING ${hex} 4 2 b2)
  string(SUBSTRING ${hex} 6 2 b3)
  set(${out} "${b3}${b2}${b1}${b0}" PARENT_SCOPE)
endfunction()

execute_process(COMMAND ${NM} ${elf} OUTPUT_VARIABLE symbols RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${elf}")
endif()
# Address of @name with the Thumb bit, as 8 lower-case hex digits
function(thumb_address name out)
  if(NOT symbols MATCHES "([0-9a-f]+) [tT] ${name}\n")
    message(FATAL_ERROR "no symbol ${name} in the image")
  endif()
  math(EXPR a "0x${CMAKE_MATCH_1} | 1" OUTPUT_FORMAT HEXADECIMAL)
  string(SUBSTRING "${a}" 2 -1 a)
  string(LENGTH "${a}" n)
  while(n LESS 8)
    set(a "0${a}")
    math(EXPR n "${n} + 1")
  endwhile()
  set(${out} ${a} PARENT_SCOPE)
endfunction()

set(failed "")
vector_word(0 sp)
if(NOT sp STREQUAL "20008000")
  list(APPEND failed "initial SP 0x${sp}, expected 0x20008000 (end of SRAM)")
endif()
foreach(entry "1;Reset_Handler" "2;NMI_Handler" "34;ADC1_2_IRQHandler" "40;TIM1_BRK_TIM15_IRQHandler")
  list(GET entry 0 index)
  list(GET entry 1 name)
  vector_word(${index} word)
  thumb_address(${name} expected)
  if(NOT word STREQUAL expected)
    list(APPEND failed "vector ${index} is 0x${word}, expected ${name} at 0x${expected}")
  else()
    message(STATUS "vector ${index}: ${name} at 0x${word}")
  endif()
endforeach()

execute_process(COMMAND ${SIZE} ${elf} OUTPUT_VARIABLE sizes)
message(STATUS "size (text = flash, data + bss = RAM):\n${sizes}")
if(NOT sizes MATCHES "\n *([0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)")
  message(FATAL_ERROR "cannot read the size of ${elf}")
endif()
math(EXPR flash "${CMAKE_MATCH_1} + ${CMAKE_MATCH_2}")
math(EXPR ram "${CMAKE_MATCH_2} + ${CMAKE_MATCH_3}")
if(flash GREATER 131072 OR ram GREATER 30720) # 128 KiB flash; 32 KiB SRAM less the 2 KiB stack reserve
  list(APPEND failed "image does not fit: ${flash} B flash, ${ram} B RAM")
endif()

# The stored configuration's pages: the .bin (from 0x08000000, where the vector table is) must end
# below them, and no symbol of the image may lie in them.
set(store_start 134344704) # 0x0801F000
set(store_end 134348800)   # 0x08020000
file(SIZE ${IMAGE_DIR}/pmstep-stm32g431.bin bin_bytes)
math(EXPR image_end "134217728 + ${bin_bytes}") # 0x08000000 + the .bin's length
math(EXPR image_end_hex "${image_end}" OUTPUT_FORMAT HEXADECIMAL)
if(image_end GREATER store_start)
  list(APPEND failed "image ends at ${image_end_hex}, inside the stored configuration's pages (from 0x0801F000)")
else()
  math(EXPR spare "${store_start} - ${image_end}")
  message(STATUS "image ends at ${image_end_hex}: ${spare} B below the stored configuration's pages (0x0801F000)")
endif()
string(REGEX MATCHALL "(^|\n)0801f[0-9a-f][0-9a-f][0-9a-f] [^\n]*" in_store "${symbols}")
if(in_store)
  string(STRIP "${in_store}" in_store)
  list(APPEND failed "symbols in the stored configuration's pages: ${in_store}")
endif()
if(failed)
  string(REPLACE ";" "\n  " failed "${failed}")
  message(FATAL_ERROR "STM32G431 image:\n  ${failed}")
endif()
