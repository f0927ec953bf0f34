#pragma once

// The one way project code includes Simbody. Debian built Simbody without NDEBUG and
// SimTK::CacheEntryInfo changes layout with it (docs/toolchain.md, trap 2): a file compiled with
// NDEBUG would corrupt memory silently, so refuse to compile instead. Link mbid_simbody.
#ifdef NDEBUG
#error "Simbody headers must be compiled with NDEBUG undefined: link the mbid_simbody target"
#endif

#include <Simbody.h>
