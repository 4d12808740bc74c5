// Shared by the fuzz targets: the read limits they run under, small enough that libFuzzer's
// -malloc_limit_mb (scripts/fuzz.sh) flags any allocation the limits should have refused.
#pragma once

#include "vc/scene/scene_input.h"

namespace vc::fuzz {

// As vc-server derives them, for a 64 KiB upload limit and a 64 MiB memory budget: at most 1 MiB
// decompressed, 32 MiB of points or tree nodes.
inline ReadOptions Limits() { return ReadLimits(uint64_t{64} << 10, uint64_t{64} << 20); }

}  // namespace vc::fuzz
