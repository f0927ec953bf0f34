#pragma once

// A decimated record is analysed below the band its spectrum showed. A strong mode above that
// band which decays within a small part of the record hardly shows in the whole record's
// spectrum, and decimation removes it without a trace: the result would lack it and still look
// complete. What the modes leave of the full-rate record tells: such a mode is a burst at its
// start, noise is the same throughout.

#include <Eigen/Core>

namespace mbid::identification {

// Squared amplitude spectrum (samples + 1 bins x channels) of `segment` mirrored: its periodic
// extension is continuous, so its ends leak nothing and its start is not windowed away.
Eigen::MatrixXd MirroredPower(const Eigen::MatrixXd& segment, double sample_interval_s,
                              Eigen::VectorXd* frequency_hz);

// `values` (samples x channels) without what lies above `top_hz`: each column mirrored about its
// start (so that its start is filtered as well as its middle, unlike a decimation filter's
// output), its FFT cut above `top_hz`, transformed back. Its last samples may ring.
Eigen::MatrixXd BandLimited(const Eigen::MatrixXd& values, double sample_interval_s, double top_hz);

// The highest frequency (Hz) at which the start of `residual` (samples x channels at the full
// sample rate: the record `values` less its fitted modes) holds 10 times the power its end
// holds, in bands of 32 bins of the spectra of its first and last 2048 samples, or halves if it
// is shorter (each mirrored, so that its ends leak nothing), and over 1e-12 of the power of the
// values' start (round-off of a noiseless record is no mode); 0 if there is none or the record
// is under 128 samples.
// Stationary noise, coloured or not, has the same power at both ends: the F ratio of 64 degrees
// of freedom exceeds 10 with probability below 1e-12.
double FindDecayingContentTop(const Eigen::MatrixXd& values, const Eigen::MatrixXd& residual,
                              double sample_interval_s);

}  // namespace mbid::identification
