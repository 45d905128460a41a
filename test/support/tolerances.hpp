// How closely the OpenCL kernels (float32) must agree with their CPU twins (double
// accumulation), by how much float arithmetic lies between input and output. Relative errors
// (rms over the output unless a test says otherwise); every cross-check names one of these.
#pragma once

namespace riner::test::tolerance {

// One rounding per element (axpy, scale, Adam's update): a few ulps of float32 (6e-8 each).
constexpr double kElementwise = 1e-6;
// One pass of float sums: a ray's samples, one MLP layer, a loss over a batch. ~1e3 terms
// summed in float round to ~1e-6 rms; 1e-5 leaves room for unlucky cancellation.
constexpr double kOnePass = 1e-5;
// Passes chained (backward through the MLP and the encoding, gradients summed over thousands of
// samples, filter + backprojection, projector and adjoint): each pass's rounding feeds the
// next, and the sums' order differs between the device and the reference.
constexpr double kChained = 1e-4;
// Whole training steps: 20 Adam steps apply the chained gradients' differences to the
// parameters and feed them back into the next step's losses.
constexpr double kTraining = 1e-3;

}  // namespace riner::test::tolerance
