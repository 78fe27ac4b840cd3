#pragma once
// Text that leaves a process in a protobuf `string` field must be valid UTF-8: protobuf refuses
// to parse a message whose string holds anything else, so an error message quoting a byte of a
// malformed input (a checkpoint entry name, a truncated key) would make the whole reply
// unreadable to the peer.
#include <string>
#include <string_view>

namespace fsi {

// `text` with every byte that is not part of a well-formed UTF-8 sequence replaced by
// "\xNN" (its value in hex); valid text is returned unchanged.
std::string valid_utf8(std::string_view text);

// The offset of the first byte of `text` that is not part of a well-formed UTF-8 sequence, or
// npos when the text is valid UTF-8.
std::size_t first_invalid_utf8(std::string_view text);

}  // namespace fsi
