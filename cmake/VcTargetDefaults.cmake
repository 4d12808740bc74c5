# vc_target_defaults(target): warnings for our own code, set per target (never at directory scope).
function(vc_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-unused-parameter
    # No fused multiply-add contraction: crossing parameters (walk.h) must round the same way on
    # every target, so traversals agree bit for bit.
    -ffp-contract=off)
  target_compile_features(${target} PUBLIC cxx_std_20)
endfunction()
