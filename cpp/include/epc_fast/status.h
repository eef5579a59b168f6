// Per-point status codes (docs/model.md, "Per-point status"). The values are shared with
// python/epc_fast/status.py: keep the two in step.
#pragma once

#include <cstdint>

namespace epc_fast {

enum class Status : std::uint8_t {
    ok = 0,              // every output finite and meaningful
    invalid = 1,         // an input outside its domain: every output NaN
    unreachable = 2,     // the SNR target cannot be met (see Cause): T_MPE = +inf
    blur_unbounded = 3,  // shake angle reached pi/2: blur = +inf, f50 = 0, EPC = 0
    beyond_table = 4,    // f50 past a tabulated MTF's end: f50 and EPC NaN, T_MPE finite
    exposure_limit = 5,  // T_MPE / frames above max_exposure_s (set in Python only): EPC NaN
};

enum class Cause : std::uint8_t {
    none = 0,
    no_light = 1,   // electron rate zero, or below 2.2e-308 e-/s (flushed), or T_MPE > 1.8e308 s
    prnu = 2,       // prnu * 10^(snr_db/20) >= 1
    full_well = 3,  // rate * T_MPE > full_well_e
};

}  // namespace epc_fast
