// The per-point parameters as the kernel reads them: one strided column per parameter.
// The order is python/epc_fast/params.py's PARAMETERS; the domains come from that table
// with every call, so the two backends judge validity by the same numbers.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "tabulated.h"

namespace epc_fast {

enum Param : int {
    illuminance_lux,
    pixel_pitch_um,
    f_number,
    focal_length_mm,
    size,  // pixel count or sensor area in mm^2 (Inputs::size_is_pixel_count)
    reflectance,
    lens_transmittance,
    field_angle_deg,
    fill_factor,
    electrons_per_lux_s_m2,
    read_noise_e,
    dark_current_e_per_s,
    prnu,
    full_well_e,
    snr_db,
    shake_deg_per_s,
    stabilization,
    jitter_um,
    wavelength_nm,
    mtf_threshold,
    binning,             // k: k x k pixels read as one output pixel (1: off)
    frames,              // n: the exposure split into n frames, aligned and summed (1: off)
    alignment_error_um,  // rms alignment error of each frame (0: off)
    wavefront_rms_waves,  // rms wavefront error in waves (0: off)
    denoise_sigma_px,     // Gaussian denoising sigma in output pixels (0: off)
    lens,                 // index of the point's lens table (Inputs::lens_tables), a whole number
    cfa_transmittance,    // a colour sensor's mean filter transmittance (1: monochrome)
    color_noise_gain,     // its colour correction's and demosaicker's noise gain (1: monochrome)
    binning_readout,      // how a binned pixel is read: 0 digital (k^2 reads), 1 charge (one)
    n_params
};

// The parameters' names, in Param's order, as the Python API spells them (params.py).
constexpr const char* param_names[n_params] = {
    "illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm", "size", "reflectance",
    "lens_transmittance", "field_angle_deg", "fill_factor", "electrons_per_lux_s_m2",
    "read_noise_e", "dark_current_e_per_s", "prnu", "full_well_e", "snr_db", "shake_deg_per_s",
    "stabilization", "jitter_um", "wavelength_nm", "mtf_threshold", "binning", "frames",
    "alignment_error_um", "wavefront_rms_waves", "denoise_sigma_px", "lens", "cfa_transmittance",
    "color_noise_gain", "binning_readout"};

// A value lies in [lo, hi] with each end open or closed, and is a whole number where `integer`
// (binning, frames); NaN lies in no domain.
struct Domain {
    double lo, hi;
    bool lo_closed, hi_closed;
    bool integer = false;

    bool contains(double v) const {
        const bool above = lo_closed ? v >= lo : v > lo;
        const bool below = hi_closed ? v <= hi : v < hi;
        return above && below && (!integer || v == std::floor(v));
    }
};

// One parameter: point i reads data[i * stride]; stride 0 broadcasts a scalar.
struct Column {
    const double* data = nullptr;
    std::ptrdiff_t stride = 0;

    double operator[](std::size_t i) const { return data[static_cast<std::ptrdiff_t>(i) * stride]; }
};

// The f50 start fitted to one spectrum (f50/guesses.h; f50/spectrum_fit.h fits it).
struct FittedStart;

// A spectrum shared by every point: weights sum to 1. Empty means monochromatic at each
// point's wavelength_nm.
struct Spectrum {
    std::vector<double> wavelengths_nm;
    std::vector<double> weights;
    // f50's start fitted to this spectrum (f50/spectrum_fit.h), or null: its lanes then take the
    // cubic start (the same f50 to f50_rtol, in more steps)
    std::shared_ptr<const FittedStart> start;

    bool polychromatic() const { return !wavelengths_nm.empty(); }

    // nm: the shortest wavelength of positive weight, the longest, and the weighted mean
    struct Extent {
        double shortest_nm, longest_nm, mean_nm;
    };
    Extent extent() const {
        Extent e{std::numeric_limits<double>::infinity(), 0.0, 0.0};
        for (std::size_t k = 0; k < wavelengths_nm.size(); ++k) {
            // selects, not calls to fmin and fmax (the same for the positive, finite wavelengths
            // a spectrum holds): start_f50 runs this once per block
            const double nm = wavelengths_nm[k];
            if (weights[k] > 0.0) e.shortest_nm = nm < e.shortest_nm ? nm : e.shortest_nm;
            e.longest_nm = nm > e.longest_nm ? nm : e.longest_nm;
            e.mean_nm += weights[k] * nm;
        }
        return e;
    }
};

struct Inputs {
    std::array<Column, n_params> columns;
    std::array<Domain, n_params> domains;
    bool size_is_pixel_count = false;
    Spectrum spectrum;
    // the call's lens tables (tabulated.h): point i's optics MTF is table lens[i]'s, in place
    // of diffraction; none: diffraction (and the spectrum) for every point
    std::vector<MtfTable> lens_tables;
    // a colour sensor's demosaicker's luminance MTF in cycles per output pixel (tabulated.h),
    // at f p_out for every point; no knots: none
    MtfTable demosaic;
};

// The parameters a readout mode may set, and the values it sets: binning k, its read-out
// (ReadoutCode), frames n and each frame's alignment error (um); a parameter the mode does not
// set keeps the call's column (sets[k] false).
constexpr int mode_params[] = {binning, binning_readout, frames, alignment_error_um};
struct ReadoutMode {
    std::array<double, 4> values{};
    std::array<bool, 4> sets{};
};

enum class TMpeSolver { closed_form, brent };

// f50's root finder (f50/solvers.h). Each keeps every iterate inside the bisection bracket of
// docs/model.md, "The cut-off frequency f50".
enum class F50Solver { halley, newton, brent, bisection };

// The floating-point type f50 is solved in (kernel.h); the rest of the model is float64.
enum class Precision { float64, float32 };

struct Options {
    Precision precision = Precision::float64;
    F50Solver f50_solver = F50Solver::halley;
    double f50_rtol = 1e-14;   // relative tolerance on f50 (f50/solvers.h: how each solver meets it)
    TMpeSolver t_mpe_solver = TMpeSolver::closed_form;
    double t_mpe_rtol = 1e-15;  // Brent's tolerance on the electrons needed
};

// The MTF factors of the share outputs (sensitivity.h), in their order.
// The binned aperture (binning) is the pixel's; the burst's alignment residual has its own, and
// so have the wavefront error's ATF (ln(D_W / D)), denoising's filter and a lens table against
// aberration-free diffraction (ln(L / D)).
enum Share : int {
    share_diffraction, share_pixel, share_motion, share_jitter, share_alignment,
    share_aberration, share_denoise, share_lens, share_demosaic, n_shares
};

// The outputs of what limits a design and how sensitive it is (sensitivity.h); null: not
// computed. Each share has a column, and so has each parameter's elasticity (elasticity[j]:
// d ln EPC / d ln parameter j), point i at index i.
struct SensitivityOutputs {
    double* share[n_shares] = {};
    double* elasticity[n_params] = {};

    bool any_share() const {
        for (double* s : share)
            if (s != nullptr) return true;
        return false;
    }
    bool any_elasticity() const {
        for (double* e : elasticity)
            if (e != nullptr) return true;
        return false;
    }
    bool any() const { return any_share() || any_elasticity(); }
};

// Output columns, contiguous. Point i of a call to evaluate_block is written at index i: the
// caller offsets the pointers to the block (Outputs::at). A null pointer: that output is not
// computed (and without f50 and EPC, f50 is not solved). No output may share memory with an
// input column: the kernel reads full blocks of contiguous columns in place (gather.h)
// while it writes outputs (the Python API copies such a column first).
struct Outputs {
    double* electron_rate_e_per_s;
    double* electrons;
    double* t_mpe_s;
    double* blur_mm;
    double* f50_cyc_per_mm;
    double* epc;
    unsigned char* status;
    unsigned char* cause;
    // Write full blocks' whole cache lines with streaming stores (stream.h): for calls whose
    // outputs are too large to stay in the caches (kernel.h streaming_for).
    bool stream = false;
    // The shares and elasticities, when asked for (sensitivity.h).
    SensitivityOutputs sensitivity = {};
    // The f50 across the motion (docs/model.md, "Resolution in both directions"): the f50 of
    // the same exposure without the motion blur. The kernel takes it with no share or
    // elasticity asked for (python/epc_fast/axes.py computes those in two passes).
    double* f50_across_cyc_per_mm = nullptr;
    // EPC counted in both directions, 4 S f50 f50_across (epc_axes="both"), and the status
    // BEYOND_TABLE where only the f50 across passes a table's end.
    bool epc_both = false;

    // The outputs from point `offset` on; a null output (not computed) stays null.
    Outputs at(std::size_t offset) const {
        auto shift = [offset](auto* p) { return p != nullptr ? p + offset : p; };
        SensitivityOutputs moved = sensitivity;
        for (double*& s : moved.share) s = shift(s);
        for (double*& e : moved.elasticity) e = shift(e);
        return Outputs{shift(electron_rate_e_per_s), shift(electrons), shift(t_mpe_s),
                       shift(blur_mm), shift(f50_cyc_per_mm), shift(epc), shift(status),
                       shift(cause), stream, moved, shift(f50_across_cyc_per_mm), epc_both};
    }

    // Whether the f50 across the motion is solved (kernel.h across): for its output, or for
    // EPC counted in both directions.
    bool across() const { return f50_across_cyc_per_mm != nullptr || epc_both; }

    // Whether the exposure's per-lane values are read after its stage: the rate, electrons,
    // T_MPE, blur or cause as outputs, or by the sensitivities (exposure/stage.h decide_lanes).
    bool exposure_values_read() const {
        return electron_rate_e_per_s != nullptr || electrons != nullptr || t_mpe_s != nullptr ||
               blur_mm != nullptr || cause != nullptr || sensitivity.any();
    }

    // The bytes a point's computed outputs take.
    std::size_t bytes_per_point() const {
        const double* values[] = {electron_rate_e_per_s, electrons, t_mpe_s, blur_mm,
                                  f50_cyc_per_mm, epc, f50_across_cyc_per_mm};
        std::size_t bytes = (status != nullptr ? 1 : 0) + (cause != nullptr ? 1 : 0);
        for (const double* v : values) bytes += v != nullptr ? sizeof(double) : 0;
        for (const double* v : sensitivity.share) bytes += v != nullptr ? sizeof(double) : 0;
        for (const double* v : sensitivity.elasticity) bytes += v != nullptr ? sizeof(double) : 0;
        return bytes;
    }
};

}  // namespace epc_fast
