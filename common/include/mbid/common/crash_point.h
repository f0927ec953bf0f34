#pragma once

namespace mbid {

// A test hook for crash consistency. When the environment variable MBID_TEST_CRASH_AT equals
// `point`, the process kills itself with SIGKILL there: the harshest interruption (a power cut
// short of lost writes), with no clean-up of any kind. Tests name each commit point in turn and
// check that nothing of the user's is lost and that the next run recovers. Unset, it costs one
// cached getenv.
void CrashPoint(const char* point);

}  // namespace mbid
