#pragma once

// Optimized operations for SUNDIALS' serial N_Vector.
//
// Debian 12 builds SUNDIALS 6.4.1 without optimization (its libraries are -O0 code: every
// vector element goes through the stack). The serial vector's operations, called hundreds of
// times per step on 8-element vectors, were 14% of `mbid update`'s instructions. SUNDIALS
// lets a vector carry its own operation table (copied to every clone), so the hot operations
// are compiled here instead. Each reproduces the arithmetic of SUNDIALS 6.4.1's serial vector,
// its special cases included, and each fused operation the generic fallback SUNDIALS runs when
// a vector has none: results are the same bits (tests/simulation/serial_vector_ops_test.cc).
// Private to simulation/.

#include <nvector/nvector_serial.h>

namespace mbid::simulation::internal {

// Replaces the hot operations of serial vector `v` (and so of its later clones). Operations
// not replaced keep SUNDIALS' own.
void UseOptimizedSerialOps(N_Vector v);

}  // namespace mbid::simulation::internal
