#pragma once

#include "mbid/identification/modal_result.h"

namespace mbid::identification {

// Marks modes that are combination tones of others (IdentifiedMode::combination) and warns of
// each.
void MarkCombinationTones(ModalResult* result);

}  // namespace mbid::identification
