# Usage: cmake -DNM=<nm> -DLIB=<libpmstep_core.a> -P check_core_symbols.cmake
# Fails if the core library needs any symbol outside a short allow-list: no heap,
# no stdio, no libm (sqrtf must compile to an instruction), nothing from the platform.
execute_process(COMMAND ${NM} -u ${LIB} OUTPUT_VARIABLE undefined RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
string(REGEX MATCHALL "U [A-Za-z0-9_.$]+" entries "${undefined}")
set(core_symbols "")
set(bad "")
foreach(entry IN LISTS entries)
  string(SUBSTRING "${entry}" 2 -1 sym)
  if(sym MATCHES "^(malloc|calloc|realloc|free|.*printf|puts|putchar|fopen|fwrite|fputs|_sbrk|sbrk|sqrtf|tanhf|expf|exit|abort)$")
    list(APPEND bad ${sym}) # named offenders, whatever the allow-list below says
    continue()
  endif()
  if(sym MATCHES "^pmstep_")
    continue() # defined in another object of the same library
  endif()
  # Compiler support: block copies, and the sanitizer runtime of the host test build.
  if(sym MATCHES "^(memcpy|memset|__asan_.*|__ubsan_.*|__sanitizer_.*|_GLOBAL_OFFSET_TABLE_)$")
    continue()
  endif()
  list(APPEND bad ${sym})
endforeach()
list(REMOVE_DUPLICATES bad)
if(bad)
  message(FATAL_ERROR "core library ${LIB} needs forbidden symbols: ${bad}")
endif()
message(STATUS "core library ${LIB}: no heap, stdio, libm or platform symbols")
