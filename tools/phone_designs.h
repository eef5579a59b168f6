// The drivers' design points and output arrays (kernel_speed.cpp, stage_costs.cpp): the points of
// epc_fast.selfcheck.random_designs (1-100k lux, 0.8-3 um, F/1.4-8, focal 2-20 mm, 1-40 mm^2,
// half with read noise 0-5 e-, shake 0-10 deg/s), every other parameter at the API's default,
// as the kernel's Inputs. Not part of the package.
#pragma once

#include <cmath>
#include <cstddef>
#include <new>
#include <random>
#include <vector>

#include "epc_fast/kernel.h"

namespace tools {

struct PhoneDesigns {
    std::vector<double> lux, pitch, f_num, focal, area, read, shake;
    double jitter_value_um = 0.0;  // every point
    // the API's defaults, in params.h's order (K: D50 with a rectangular QE)
    double defaults[epc_fast::n_params] = {0, 0, 0, 0, 0, 0.4, 1.0, 0.0, 1.0, 2557705539053827.5,
                                           0, 0, 0, INFINITY, 30, 4.39, 1, 0, 550, 0.5,
                                           1, 1, 0, 0, 0, 0, 1, 1, 0};
    static_assert(epc_fast::n_params == 29, "a default for every parameter");

    PhoneDesigns(std::size_t n, double jitter_um_) : jitter_value_um(jitter_um_) {
        std::mt19937_64 rng(1);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (auto* v : {&lux, &pitch, &f_num, &focal, &area, &read, &shake}) v->resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            lux[i] = std::pow(10.0, 5.0 * u(rng));
            pitch[i] = 0.8 + 2.2 * u(rng);
            f_num[i] = 1.4 + 6.6 * u(rng);
            focal[i] = 2.0 + 18.0 * u(rng);
            area[i] = 1.0 + 39.0 * u(rng);
            read[i] = u(rng) < 0.5 ? 0.0 : 5.0 * u(rng);
            shake[i] = 10.0 * u(rng);
        }
    }
    PhoneDesigns(const PhoneDesigns&) = delete;  // inputs() points into this object
    PhoneDesigns& operator=(const PhoneDesigns&) = delete;

    // Every domain open to everything (the drivers' points are all valid).
    epc_fast::Inputs inputs() const {
        using namespace epc_fast;
        Inputs in;
        for (int j = 0; j < n_params; ++j) {
            in.columns[j] = Column{&defaults[j], 0};
            in.domains[j] = Domain{-1e300, INFINITY, true, true};
        }
        in.columns[illuminance_lux] = {lux.data(), 1};
        in.columns[jitter_um] = {&jitter_value_um, 0};
        in.columns[pixel_pitch_um] = {pitch.data(), 1};
        in.columns[f_number] = {f_num.data(), 1};
        in.columns[focal_length_mm] = {focal.data(), 1};
        in.columns[size] = {area.data(), 1};
        in.columns[read_noise_e] = {read.data(), 1};
        in.columns[shake_deg_per_s] = {shake.data(), 1};
        return in;
    }
};

// A std::allocator that aligns to 64 bytes, as the package's own output memory is
// (output_cache.h), so that large calls stream their outputs here as they do there (stream.h).
template <class T>
struct Aligned64 {
    using value_type = T;
    Aligned64() = default;
    template <class U>
    Aligned64(const Aligned64<U>&) {}
    T* allocate(std::size_t n) {
        return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{64}));
    }
    void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t{64}); }
    template <class U>
    bool operator==(const Aligned64<U>&) const { return true; }
    template <class U>
    bool operator!=(const Aligned64<U>&) const { return false; }
};

// Preallocated arrays for every output of n points, and the kernel's Outputs over them, which
// stream as a call of n points does in the package (kernel.h streaming_for).
struct OutputArrays {
    std::vector<double, Aligned64<double>> values[6];
    std::vector<unsigned char, Aligned64<unsigned char>> status, cause;

    explicit OutputArrays(std::size_t n) : status(n), cause(n) {
        for (auto& v : values) v.assign(n, 0.0);
    }
    epc_fast::Outputs outputs() {
        const epc_fast::Outputs out{values[0].data(), values[1].data(), values[2].data(),
                                    values[3].data(), values[4].data(), values[5].data(),
                                    status.data(),    cause.data()};
        return epc_fast::streaming_for(out, status.size());
    }
};

}  // namespace tools
