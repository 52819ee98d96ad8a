# ctest labels by test name: `fast` (seconds in all, run while editing:
# ctest --preset host -L fast), `slow` (closed loops, oracle, robustness runs, cross builds),
# and `pil` (processor in the loop on QEMU, also slow). A label a test already has (core,
# sil, ...) is kept. Call pmstep_label_tests_here() at the end of each CMakeLists.txt that adds tests.
function(pmstep_label_tests_here)
  get_directory_property(tests TESTS)
  foreach(test IN LISTS tests)
    if(test MATCHES "^pil\\." OR test MATCHES "^console\\.qemu_(stepdir_)?e2e$")
      set(speed pil slow)
    elseif(test MATCHES "^(closed_loop|robustness|oracle)\\."
           OR test MATCHES "^gain_check\\.(theory_and_sil|cli_doa_smoke)$"
           OR test MATCHES "^sil_cli\\.scenario_"
           OR test MATCHES "^hal\\.stm32g4_image"
           OR test MATCHES "^console\\.host_tool$"
           OR test MATCHES "^console\\.qemu_store_e2e$"
           OR test MATCHES "^fuzz\\.(core|scenario|console)_run$"
           OR test MATCHES "^docs\\.quickstart$"
           OR test MATCHES "^eva\\.")
      set(speed slow)
    else()
      set(speed fast)
    endif()
    get_test_property(${test} LABELS labels)
    if(NOT labels)
      set(labels "")
    endif()
    list(APPEND labels ${speed})
    list(REMOVE_DUPLICATES labels)
    set_tests_properties(${test} PROPERTIES LABELS "${labels}")
  endforeach()
endfunction()
