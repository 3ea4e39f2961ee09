#pragma once
// The runtime's CAN protocol, as one codec in protocol/:
//
//   signal_codec.hpp   a DBC signal (Intel byte order, any start bit, 1..32
//                      bits, scale, offset, range) and how it is read and written
//   message_codec.hpp  a DBC message and the checks before decoding one
//   messages.hpp       the table: every message and signal, the enums' value
//                      tables, the acceptance filter of each frame group, the
//                      DBC file's receivers and comments
//   frames.hpp         one typed struct per message, and which field carries
//                      which signal
//   frame_codec.hpp    encode() and decode() for every typed struct, walking
//                      its message's signals in the table
//
// The table is the protocol's one description, identifiers included: code
// and documents point at it instead of listing them again. The build writes the DBC file for candump/cantools
// users from it (firmware/protocol/write_dbc.cpp, into
// <build>/firmware/protocol/cdcr.dbc); a host test reads that file back with
// a parser of its own, and golden frames written by hand
// (host_tests/firmware/protocol_golden_frames_test.cpp) pin every message's
// bytes.

#include "cdcr/firmware/protocol/fd_frames.hpp"
#include "cdcr/firmware/protocol/frame_codec.hpp"
#include "cdcr/firmware/protocol/frames.hpp"
#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
