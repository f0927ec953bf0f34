#pragma once

// Gaps (empty or NaN cells) in a record's columns: refused, or filled by linear interpolation
// between the neighbouring samples of the uniform grid (docs/records.md, "Gaps").

#include <vector>

namespace mbid::records::internal {

// Index of the first NaN in `values`, or -1.
int FirstGap(const std::vector<double>& values);

// Replaces each run of NaN by the straight line between its neighbours; returns how many
// values were filled. A run touching the first or last sample has only one neighbour: sets
// `*unfillable` to its first index and returns without filling anything.
int FillGapsLinear(std::vector<double>* values, int* unfillable);

}  // namespace mbid::records::internal
