// The per-lane state of one block of points, laid out as structure of arrays so that every
// stage of the kernel (kernel.h, exposure/stage.h, f50/stage.h) is a loop over lanes that
// vectorises.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "params.h"
#include "tabulated.h"

namespace epc_fast {

constexpr std::size_t block_size = 64;

namespace detail {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

// Every stage runs over all block_size lanes, whatever the number n of real points: lanes past
// n hold stand-ins and are never written out. A constant, aligned trip count leaves the
// vectoriser no scalar prologue or epilogue, so every lane runs the same instructions and a
// point's result does not depend on its place in the block.
//
// T is the type f50 is solved in (f50/solvers.h): float64, or float32 in the float32 precision
// mode.
// The parameters, the exposure stage and the outputs are float64 in both.
// A lane flag of a loop over T. On AVX2 (without AVX-512) it is as wide as the loop's lanes
// (64 bits in float64 loops, 32 in float32 ones): AVX2 keeps a mask in a vector register of
// the lanes' width, so such a loop tests and sets the flag in its own width, with no widening
// of bytes to masks and narrowing back. AVX-512 keeps masks in its mask registers, which move
// to and from bytes in one instruction, and SSE2's narrow lanes pack bytes cheaply: there
// bytes are the faster flags, and a Block's flags take an eighth of the cache. Defining
// EPC_FAST_BYTE_FLAGS gives bytes on AVX2 too, to time both (tools/kernel_speed.cpp).
#if defined(__AVX2__) && !defined(__AVX512F__) && !defined(EPC_FAST_BYTE_FLAGS)
template <class T>
using LaneFlag = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
#else
template <class T>
using LaneFlag = unsigned char;
#endif

// The columns a Block's broadcast rows were set up for (gather.h): the Inputs' columns
// as they were (data and stride), whether the illuminance column was replaced, whether a
// broadcast value is outside its domain, the varying columns and the broadcast ones with
// their values' bits as read.
struct ColumnLayout {
    bool set = false, replaced = false, invalid = false;
    int n_varying = 0, n_broadcast = 0;
    int varying[n_params];
    int broadcast[n_params];
    std::array<Column, n_params> columns;
    std::uint64_t bits[n_params];  // broadcast column broadcast[k]'s value, bits[k]
};

// Where a block's denoising weights come from (denoise.h): one row for a broadcast sigma, a row
// per tap of every lane's, or formed at each evaluation (a lane's R beyond the cached taps).
enum class DenoiseWeights : unsigned char { same, cached, formed };

template <class T>
struct alignas(64) Block {
    std::size_t n;
    // parameters: x[j] points at block_size values, in the caller's column itself (a full
    // block of a contiguous column whose points are all valid: nothing to copy) or in
    // x_store[j] (a broadcast row, a partial or strided block, or a block with invalid lanes,
    // which hold harmless stand-ins there)
    const double* x[n_params];
    double x_store[n_params][block_size];
    std::uint32_t uniform;  // bit j: parameter j is broadcast (the same in every lane)
    double broadcast[n_params];  // a broadcast parameter's value (its stand-in if invalid)
    bool is_broadcast(int j) const { return (uniform & (std::uint32_t{1} << j)) != 0; }
    // whether parameter j is broadcast with the value v (the terms a block can drop)
    bool broadcast_is(int j, double v) const { return is_broadcast(j) && broadcast[j] == v; }
    // bit j: row x_store[j] holds row_value[j] in every lane, from an earlier block on the same
    // Block (each thread of a call keeps one: kernel.h), so a broadcast row is filled once
    std::uint32_t row_filled = 0;
    double row_value[n_params];
    ColumnLayout layout;
    // a broadcast field angle's cos(theta) and SNR target's 10^(snr/20), from the last block
    // that computed them (NaN keys: none yet)
    double memo_angle_deg = nan, memo_cos_theta = 1.0, memo_snr_db = nan, memo_root_s = 1.0;
    // flags are bytes, not bool: the lane loops vectorise on them; `valid` is read and set
    // only in float64 loops (gather, the exposure stage), so it is as wide as their lanes
    LaneFlag<double> valid[block_size];
    double rate[block_size], electrons[block_size], t_mpe[block_size], blur[block_size];
    // the exposure stage's flags (float64 loops, so as wide as their lanes): PRNU caps the
    // lane; the lane's products leave the range the vector path vouches for (exposure_lane
    // redoes it); the rate's partial products stay moderate
    LaneFlag<double> capped[block_size], slow[block_size], rate_normal[block_size];
    // binning and bursts (exposure/sensor.h sensor_terms): the read noise, dark current, PRNU,
    // full well and stabilisation as the exposure sees them, and k^2, in a block that has them
    double sensor_store[6][block_size];
    bool sensor = false;
    // what the exposure stage decides (exposure/stage.h): each lane's Status and Cause codes
    // (status.h), the blur as written out (NaN where undefined, +inf where unbounded), the
    // lanes to solve
    unsigned char status[block_size], cause[block_size];
    double blur_out[block_size];
    LaneFlag<T> solve[block_size];
    double scratch[5][block_size];  // the exposure stage's, then f50's start's
    unsigned char row_code[block_size];  // f50's start: the accurate start's row (f50/start.h)
    // float32 mode: a lane f50 cannot be solved for in float32 (a length outside
    // [2^-40, 2^40] mm); the block is redone in float64 for it (kernel.h)
    unsigned char wide[block_size];
    // the f50 across the motion (kernel.h across_f50): as written out (NaN unless solved), and
    // whether it passed a lens table's end
    double across_out[block_size];
    unsigned char across_beyond[block_size];
    // f50, in T: per-point lengths (mm) the frequency multiplies, the other inputs of the
    // solve, the bracket, the iterate
    T lambda_f_mm[block_size], aperture_mm[block_size], jitter_mm[block_size];
    T blur_mm[block_size], threshold[block_size], f_number[block_size];
    // binning where a < 1 (mtf.h binned_lengths_mm): the array factor's pitch (0: none) and k
    T bin_pitch_mm[block_size], bin_k[block_size];
    T lo[block_size], hi[block_size], at[block_size];
    // the system MTF at `at`, its log-slope R = M'/M and S = sum of (M_i''/M_i - (M_i'/M_i)^2)
    // over the factors, so that M''/M = R^2 + S
    T mtf[block_size], slope[block_size], curvature[block_size];
    T denominator[block_size];  // monochromatic diffraction's slopes' (f50/system_mtf.h)
    T previous_step[block_size];  // Newton/Halley: each lane's previous step
    // Newton/Halley: the step tolerance last derived from f50_rtol (a cube or square root)
    T memo_rtol = T(-1), memo_step_rtol = T(0);
    bool memo_halley = false;
    T f50[block_size];
    LaneFlag<T> active[block_size];  // the solvers' lanes still stepping
    // Halley/Newton: a lane whose start is certified within f50_rtol (f50/settle.h,
    // certified_start_error) takes it as f50 without a step; n_settled counts them
    LaneFlag<T> settled[block_size];
    int n_settled = 0;
    double certified_start[block_size] = {};  // float32: the settled lanes' starts, in float64
    // The terms beyond the paper's camera, last: a block without them never touches these, and
    // the arrays every block uses stay together, as compact in the caches as without them.
    // the wavefront error and denoising (aberration.h, denoise.h), in a block whose lanes to solve
    // have them (`aberration`, `denoise`): the ATF's depth a = (W / 0.18)^2; the output pitch (mm),
    // the filter's 1 / (2 sigma^2), 1 / Z and reach R, and the largest R (`denoise_taps`); the
    // filter's transfer with two derivatives, per lane
    T atf_depth[block_size];
    T output_pitch_mm[block_size], denoise_scale[block_size], denoise_inverse_norm[block_size];
    T denoise_reach[block_size];
    T denoise_value[block_size], denoise_d1[block_size], denoise_d2[block_size];
    bool aberration = false, denoise = false;
    // the call's lens tables (Inputs::lens_tables; null: none): every lane's optics MTF is its
    // table's, the lane's index in x[lens]
    const std::vector<MtfTable>* lens_tables = nullptr;
    // a colour sensor's demosaicker's table (Inputs::demosaic; null: none), at f p_out
    const MtfTable* demosaic_table = nullptr;
    int denoise_taps = 0;
    // the filter's weights h_i (denoise_lanes): a broadcast sigma's, memo_denoise_h[i - 1], kept
    // from block to block with its R, 1 / (2 sigma^2) and 1 / Z; else every lane's, tap i row
    // i - 1, where the block's largest R is at most denoise_cached_taps (sigma <= 5 px): formed
    // once a block, not at every evaluation of the transfer
    static constexpr int denoise_cached_taps = 20;
    T denoise_h[denoise_cached_taps][block_size];
    DenoiseWeights denoise_weights = DenoiseWeights::formed;
    double memo_denoise_sigma = nan, memo_denoise_reach = 0.0, memo_denoise_scale = 0.0,
           memo_denoise_inverse_norm = 1.0;
    T memo_denoise_h[denoise_cached_taps] = {};
    // denoising's noise gain in the exposure stage: sqrt(g) per lane, where `gained`
    double root_gain[block_size];
    bool gained = false;
    // a broadcast sigma's and colour noise gain's sqrt(g)
    double memo_sigma = nan, memo_color_gain = nan, memo_root_gain = 1.0;
    // Halley/Newton: the lanes that do not stop on their first step (a start fitted to a lens
    // table, f50/start.h lens_fitted_starts), and whether any does (last: the arrays before it
    // keep their places)
    LaneFlag<T> step_twice[block_size];
    bool step_twice_any = false;
};

}  // namespace detail
}  // namespace epc_fast
