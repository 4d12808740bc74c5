# Run after a test suite's executable is linked (cmake -P, from vc_add_test_suite with
# VC_TEST_PER_SUITE): lists its gtest tests that FILTER matches and writes OUT, a ctest script with
# one test per run of at most CHUNK tests of one gtest test suite (`Suite`, or `Suite#2`, ... when a
# suite has more), each running its tests in one process by their full names. Why: a process under
# ASan costs 0.14-0.24 s to start and stop, about a fifth of the asan stage's test CPU over 1,160
# processes (README, "Testing"; docs/BENCHMARKS.md, "CI time").
# Inputs: EXE, OUT, FILTER (a gtest filter; empty: every test), LABELS (one label or empty),
# SUFFIX (added to each name: keeps the names of two discoveries of one executable apart), CHUNK,
# WORKDIR.
cmake_minimum_required(VERSION 3.25)

set(filter_arg "")
if(FILTER)
  set(filter_arg "--gtest_filter=${FILTER}")
endif()
execute_process(COMMAND "${EXE}" --gtest_list_tests ${filter_arg} OUTPUT_VARIABLE listing RESULT_VARIABLE rc
                ERROR_VARIABLE errors TIMEOUT 60)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${rc}): ${errors}")
endif()

string(REPLACE ";" "\\;" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(suites "")
set(suite "")
foreach(line IN LISTS lines)
  string(REGEX REPLACE " *#.*$" "" line "${line}")  # "  # GetParam() = ..." and the like
  if(line MATCHES "^([^ ]+)\\.$")
    set(suite "${CMAKE_MATCH_1}")
    list(APPEND suites "${suite}")
    set(tests_of_${suite} "")
  elseif(suite AND line MATCHES "^  ([^ ]+)$")
    list(APPEND tests_of_${suite} "${suite}.${CMAKE_MATCH_1}")
  endif()
endforeach()

set(script "")
foreach(suite IN LISTS suites)
  list(LENGTH tests_of_${suite} n)
  if(n EQUAL 0)
    continue()
  endif()
  math(EXPR runs "(${n} + ${CHUNK} - 1) / ${CHUNK}")
  math(EXPR last_run "${runs} - 1")
  foreach(r RANGE ${last_run})
    math(EXPR begin "${r} * ${CHUNK}")
    list(SUBLIST tests_of_${suite} ${begin} ${CHUNK} chunk)
    list(LENGTH chunk count)
    list(JOIN chunk ":" names)
    set(name "${suite}${SUFFIX}")
    if(runs GREATER 1)
      math(EXPR number "${r} + 1")
      set(name "${name}#${number}")
    endif()
    string(APPEND script "add_test([==[${name}]==] [==[${EXE}]==] [==[--gtest_filter=${names}]==])\n")
    # COST: the runs with more tests start first on a fresh build, which has no timings yet. No
    # SKIP_REGULAR_EXPRESSION: it overrides the exit code, and one of several tests skipping must
    # not hide another's failure; a skipped test is named in its run's gtest output.
    string(APPEND script "set_tests_properties([==[${name}]==] PROPERTIES WORKING_DIRECTORY [==[${WORKDIR}]==]"
                         " COST ${count}")
    if(LABELS)
      string(APPEND script " LABELS [==[${LABELS}]==]")
    endif()
    string(APPEND script ")\n")
  endforeach()
endforeach()
file(WRITE "${OUT}" "${script}")
