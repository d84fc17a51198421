# Registers one gtest binary's tests with ctest, one ctest test per gtest
# test suite (all of `Suite.*` in one process) rather than one per TEST.
#
# Why: every test process loads the renderer's ~260 shared libraries
# (OpenImageIO and what it pulls in); that costs ~0.2 s per process on an idle
# machine and twice that under load, which over ~500 tests was a third of the
# suite's time. One process per suite runs exactly the same tests and
# assertions; gtest still names each failing TEST in the output
# (ctest --output-on-failure).
#
# Tests named in TESSERA_TESTS_ON_THEIR_OWN_<area> (CMakeLists.txt) keep a ctest test
# of their own: slow ones, so that ctest -j runs them beside the rest instead
# of inside one long suite, and ones that may GTEST_SKIP, so that ctest still
# reports them as skipped (a suite's process cannot: ctest's skip expression
# would mark the whole suite skipped, failures included). A name in that list
# that the binary does not have is an error, not a test that silently runs
# nothing.
#
# Included by ctest (TEST_INCLUDE_FILES) with _tessera_bin, _tessera_area,
# _tessera_own and _tessera_cmake set: it lists the binary's tests when ctest runs, as
# gtest_discover_tests(... DISCOVERY_MODE PRE_TEST) does.

if(NOT EXISTS "${_tessera_bin}")
  add_test(${_tessera_area}_tests_NOT_BUILT ${_tessera_area}_tests_NOT_BUILT)
  return()
endif()
execute_process(COMMAND "${_tessera_bin}" --gtest_list_tests
                OUTPUT_VARIABLE _out RESULT_VARIABLE _rc TIMEOUT 60)
if(NOT _rc EQUAL 0)
  add_test(${_tessera_area}_tests_LIST_FAILED ${_tessera_area}_tests_LIST_FAILED)
  return()
endif()

string(REPLACE ";" "" _out "${_out}")
string(REPLACE "\n" ";" _lines "${_out}")
set(_suites "")
set(_suite "")
set(_found_own "")
foreach(_line IN LISTS _lines)
  if(_line MATCHES "^([A-Za-z_][A-Za-z0-9_/]*)\\.")
    set(_suite "${CMAKE_MATCH_1}")
    list(APPEND _suites "${_suite}")
    set(_excluded_${_suite} "")
  elseif(_suite AND _line MATCHES "^  ([A-Za-z_][A-Za-z0-9_/]*)")
    set(_name "${_suite}.${CMAKE_MATCH_1}")
    list(FIND _tessera_own "${_name}" _i)  # (ctest scripts have no IN_LIST)
    if(_i GREATER -1)
      list(APPEND _found_own "${_name}")
      list(APPEND _excluded_${_suite} "${_name}")
      add_test("${_name}" "${_tessera_bin}" "--gtest_filter=${_name}")
      # COST: started first by ctest -j even without timings from an earlier run.
      set_tests_properties("${_name}" PROPERTIES LABELS "${_tessera_area}" COST 1000
                           SKIP_REGULAR_EXPRESSION "\\[  SKIPPED \\]")
    else()
      set(_has_rest_${_suite} TRUE)
    endif()
  endif()
endforeach()

foreach(_s IN LISTS _suites)
  if(_has_rest_${_s})
    set(_filter "${_s}.*")
    if(_excluded_${_s})
      string(REPLACE ";" ":" _minus "${_excluded_${_s}}")
      set(_filter "${_filter}:-${_minus}")
    endif()
    add_test("${_s}" "${_tessera_bin}" "--gtest_filter=${_filter}")
    set_tests_properties("${_s}" PROPERTIES LABELS "${_tessera_area}")
  endif()
endforeach()

# Names listed for this area that the binary does not have (renamed or
# removed tests): a failing test, so that the list is kept up to date.
foreach(_name IN LISTS _tessera_own)
  list(FIND _found_own "${_name}" _i)
  if(_i EQUAL -1)
    add_test("${_name}_NOT_FOUND" "${_tessera_cmake}" -E echo
             "${_name} is in TESSERA_TESTS_ON_THEIR_OWN_${_tessera_area} but not in ${_tessera_area}_tests")
    set_tests_properties("${_name}_NOT_FOUND" PROPERTIES LABELS "${_tessera_area}" WILL_FAIL TRUE)
  endif()
endforeach()
