#pragma once

#include <string>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"

namespace mbid::identification {

// Identifies the modes of a free-decay record (what `mbid identify` does).
//
// hankel-nls (default): the block-Hankel SVD of the record (hankel_svd.h) gives the signal
// order (singular values above the noise floor) and initial poles, kept if they are stable
// across orders; a Ceres refinement (refinement.h) then fits all poles and amplitudes; modes
// outside the step-5 limits or not significant (significance.h) are dropped and the fit
// repeated.
// prony-svd: the paper's steps 2-5 (prony_svd.h) with p = options.prony.order, then the
// same linear amplitude fit and significance test, no refinement.
// Both: amplitudes, phases, reconstruction and correlation on the full-rate record; the
// standard deviations of frequency and decay from the Fisher information at the estimate
// (for prony-svd this is the bound an efficient estimator would reach, not its own error);
// A1..Ap of eq. 2 by eq. 5; spectrum (step 1) and stabilization data if asked.
//
// Errors: InputError (source "identification options" for an option out of range, otherwise
// `origin`) for a channel that is not in the record, NaN/Inf samples, a constant or all-zero
// channel, a window with too few samples for the method's order, and a frequency band above
// the Nyquist frequency of the (decimated) record; NumericalError("identification",
// "no modes found: <reason>") when nothing significant is in the record (pure noise).
ModalResult Identify(const Measurement& measurement, const IdentificationOptions& options,
                     const std::string& origin = "measurement");

}  // namespace mbid::identification
