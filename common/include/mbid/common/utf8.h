#pragma once

// UTF-8 checks for text read from files. Names and units end up in JSON summaries, which must
// be UTF-8: a bad byte is refused where it is read, naming the file and place (exit 2), rather
// than when the summary is written after the whole cycle.

#include <cstddef>
#include <string>
#include <string_view>

namespace mbid {

// The offset of the first byte that does not belong to a valid UTF-8 sequence (overlong forms,
// surrogates and code points above U+10FFFF are invalid), or std::string_view::npos.
size_t FindInvalidUtf8(std::string_view text);

// Throws InputError(source, field, ...) naming the bad byte if `text` is not valid UTF-8.
void ValidateUtf8(std::string_view text, const std::string& source, const std::string& field);

// The same for a whole text file, which also holds no NUL byte: the error names the line and
// column (1-based) of the byte.
void ValidateUtf8Text(std::string_view text, const std::string& source);

}  // namespace mbid
