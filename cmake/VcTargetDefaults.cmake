# vc_target_defaults(target): warnings for our own code, set per target (never at directory scope).
function(vc_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-unused-parameter
    # No fused multiply-add contraction: crossing parameters (walk.h) must round the same way on
    # every target, so traversals agree bit for bit.
    -ffp-contract=off)
  target_compile_features(${target} PUBLIC cxx_std_20)
endfunction()

# VC_FUZZ_COVERAGE_FLAGS: the coverage counters that guide libFuzzer (the asan preset sets them).
# They go only into the libraries a fuzz target reaches (vc_fuzzed_target: base, scene, plan,
# report, wire, server_jobs; fuzz/CMakeLists.txt); counters in the tests, the client or the gRPC
# service would guide nothing and cost about a fifth of each file's compile time under the sanitizers
# (README, "Testing").
set(VC_FUZZ_COVERAGE_FLAGS "" CACHE STRING "Coverage flags for the libraries the fuzzers reach")
function(vc_fuzzed_target target)
  if(VC_FUZZ_COVERAGE_FLAGS)
    separate_arguments(flags UNIX_COMMAND "${VC_FUZZ_COVERAGE_FLAGS}")
    target_compile_options(${target} PRIVATE ${flags})
  endif()
endfunction()
