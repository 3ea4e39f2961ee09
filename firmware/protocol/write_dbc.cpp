// Writes the protocol's DBC file from the codec's table
// (cdcr/firmware/protocol/messages.hpp), so that candump and cantools users
// decode exactly the frames the runtime packs. The build runs it; nobody
// edits its output.
//
// Usage: cdcr_write_dbc <out.dbc> [--fd] [--id-base BASE]
//
// --fd writes the database of a CAN FD bus: every message as an FD frame,
// and the FD messages (POSE_FD, TARGET_FD, CABLE_SETPOINTS_FD) after them.
// BASE (decimal or 0x-hexadecimal; default 0x100) moves every identifier
// with the protocol's window (messages.hpp, kDefaultIdBase): the DBC of a
// runtime started with that base. The file is written to a temporary name
// beside it and renamed, so a reader never sees half of it.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cdcr/firmware/protocol/message_codec.hpp"
#include "cdcr/firmware/protocol/messages.hpp"
#include "cdcr/firmware/protocol/signal_codec.hpp"
#include "cdcr/hal/shifted_can_bus.hpp"

namespace cdcr::firmware::protocol {
namespace {

// A number as DBC editors write it ("0.01", "4294967295", "1E-005",
// "3.0518509475997192E-005"): 15 significant digits, or 17 where 15 do not
// read back as the same double, so a reader's strtod gets the table's value
// bit for bit.
std::string dbc_number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.15G", value);
  if (std::strtod(text, nullptr) != value) std::snprintf(text, sizeof text, "%.17G", value);
  std::string number = text;
  // Three exponent digits, as the DBC editors print them.
  const auto e = number.find('E');
  if (e != std::string::npos) {
    const std::string sign = number.substr(e + 1, 1);
    std::string exponent = number.substr(e + 2);
    while (exponent.size() < 3) exponent.insert(0, "0");
    number = number.substr(0, e + 1) + sign + exponent;
  }
  return number;
}

// A DBC string cannot hold a double quote.
std::string quoted(const std::string& text, const std::string& where) {
  if (text.find('"') != std::string::npos) throw std::runtime_error(where + ": a DBC string cannot hold '\"'");
  return '"' + text + '"';
}

std::string frame_name(const MessageSpec& message, int index) {
  return message.id_count == 1 ? message.name : message.name + std::string("_") + std::to_string(index);
}

std::string with_segment(std::string text, int segment) {
  const std::string mark = "{segment}";
  for (auto at = text.find(mark); at != std::string::npos; at = text.find(mark)) {
    text.replace(at, mark.size(), std::to_string(segment));
  }
  return text;
}

void check_notes(const MessageNotes& notes) {
  for (const SignalNote& note : notes.signals) {
    bool found = false;
    for (const SignalSpec* signal : notes.message->signals) found = found || signal == note.signal;
    if (!found) {
      throw std::runtime_error(std::string(notes.message->name) + ": a note for " + note.signal->name +
                               ", which is not one of its signals");
    }
  }
}

// One message as the DBC lists it: a classical message at one of its
// identifiers, or an FD message whose signals are its parts' signals moved
// to their parts' bytes.
struct DbcSignal {
  const SignalSpec* spec;
  std::string name;
  int start_bit;
  const char* note;  // "" without a CM_ SG_
};

struct DbcMessage {
  std::uint32_t id;
  std::string name;
  int bytes;
  const char* sender;
  const char* receiver;
  std::string comment;
  std::vector<DbcSignal> signals;
};

const char* note_of(const MessageNotes& notes, const SignalSpec* signal) {
  for (const SignalNote& note : notes.signals) {
    if (note.signal == signal) return note.text;
  }
  return "";
}

const MessageNotes& notes_of(const MessageSpec* message) {
  for (const MessageNotes* notes : kMessageNotes) {
    if (notes->message == message) return *notes;
  }
  throw std::runtime_error(std::string(message->name) + ": a part with no notes in kMessageNotes");
}

std::vector<DbcMessage> classical_messages() {
  std::vector<DbcMessage> messages;
  for (const MessageNotes* notes : kMessageNotes) {
    check_notes(*notes);
    const MessageSpec* message = notes->message;
    for (int i = 0; i < message->id_count; ++i) {
      DbcMessage out{message->id + std::uint32_t(i), frame_name(*message, i), message->dlc, message->sender,
                     notes->receiver,  with_segment(notes->comment, i),   {}};
      for (const SignalSpec* signal : message->signals) {
        out.signals.push_back({signal, signal->name, signal->start_bit, note_of(*notes, signal)});
      }
      messages.push_back(std::move(out));
    }
  }
  return messages;
}

// Part k's signals are named after its message (POSE_UNCERTAINTY_FLAGS), a
// per-segment part's after its place in the frame (CABLE_SETPOINT_2_L1: the
// frame's third segment), and sit 64 k bits further.
std::vector<DbcMessage> fd_messages() {
  std::vector<DbcMessage> messages;
  for (const FdMessageNotes* notes : kFdMessageNotes) {
    const FdMessageSpec* message = notes->message;
    for (int i = 0; i < message->id_count; ++i) {
      DbcMessage out{message->id + std::uint32_t(i),
                     message->id_count == 1 ? message->name : message->name + std::string("_") + std::to_string(i),
                     message->length, message->sender, notes->receiver, notes->comment, {}};
      for (int k = 0; k < message->part_count; ++k) {
        const MessagePart& part = message->parts[k];
        const MessageNotes& part_notes = notes_of(part.message);
        const std::string prefix = std::string(part.message->name) + "_" +
                                   (part.message->id_count > 1 ? std::to_string(k) + "_" : std::string());
        for (const SignalSpec* signal : part.message->signals) {
          out.signals.push_back({signal, prefix + signal->name, signal->start_bit + 8 * kPartBytes * k,
                                 note_of(part_notes, signal)});
        }
      }
      messages.push_back(std::move(out));
    }
  }
  return messages;
}

void write_signal(std::ostream& out, const DbcSignal& signal, const char* receiver) {
  const SignalSpec& spec = *signal.spec;
  out << " SG_ " << signal.name << " : " << signal.start_bit << '|' << int(spec.length_bits) << '@'
      << kDbcIntelByteOrder << (spec.is_signed ? '-' : '+') << " (" << dbc_number(spec.factor) << ','
      << dbc_number(spec.offset) << ") [" << dbc_number(spec.minimum) << '|' << dbc_number(spec.maximum) << "] "
      << quoted(spec.unit, signal.name) << ' ' << receiver << '\n';
}

// The classical database, or with `fd` that of a CAN FD bus: every message
// an FD frame (the runtime sends every frame of such a bus as one), and the
// FD messages after the classical ones.
void write_dbc(std::ostream& out, std::uint32_t base, bool fd) {
  const std::uint32_t shift = id_offset(base);
  const auto on_bus = [shift](std::uint32_t id) { return hal::ShiftedCanBus::shifted(id, shift); };
  std::vector<DbcMessage> messages = classical_messages();
  if (fd) {
    for (DbcMessage& message : fd_messages()) messages.push_back(std::move(message));
  }

  out << "VERSION " << quoted(kDbcVersion, "VERSION") << "\n\n";
  out << "NS_ :\n\nBS_:\n\nBU_:";
  for (const char* node : kDbcNodes) out << ' ' << node;
  out << "\n\n";
  for (const DbcMessage& message : messages) {
    out << "BO_ " << on_bus(message.id) << ' ' << message.name << ": " << message.bytes << ' ' << message.sender
        << '\n';
    for (const DbcSignal& signal : message.signals) write_signal(out, signal, message.receiver);
    out << '\n';
  }

  out << "CM_ " << quoted(kDbcComment, "the database comment") << ";\n";
  for (const DbcMessage& message : messages) {
    if (!message.comment.empty()) {
      out << "CM_ BO_ " << on_bus(message.id) << ' ' << quoted(message.comment, message.name) << ";\n";
    }
    for (const DbcSignal& signal : message.signals) {
      if (*signal.note == '\0') continue;
      out << "CM_ SG_ " << on_bus(message.id) << ' ' << signal.name << ' '
          << quoted(signal.note, message.name + "." + signal.name) << ";\n";
    }
  }

  if (fd) {
    // Vector's attributes for an FD database, as CANdb++, cantools and
    // canmatrix read them: 14 is StandardCAN_FD.
    out << "BA_DEF_  \"BusType\" STRING ;\n";
    out << "BA_DEF_ BO_  \"VFrameFormat\" ENUM  \"StandardCAN\",\"ExtendedCAN\",\"reserved\",\"J1939PG\","
           "\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\",\"reserved\","
           "\"reserved\",\"reserved\",\"StandardCAN_FD\",\"ExtendedCAN_FD\";\n";
    out << "BA_DEF_DEF_  \"BusType\" \"CAN FD\";\n";
    out << "BA_DEF_DEF_  \"VFrameFormat\" \"StandardCAN_FD\";\n";
    out << "BA_ \"BusType\" \"CAN FD\";\n";
    for (const DbcMessage& message : messages) out << "BA_ \"VFrameFormat\" BO_ " << on_bus(message.id) << " 14;\n";
  }

  for (const DbcMessage& message : messages) {
    for (const DbcSignal& signal : message.signals) {
      const SignalSpec& spec = *signal.spec;
      if (spec.values.count == 0) continue;
      out << "VAL_ " << on_bus(message.id) << ' ' << signal.name;
      for (int k = 0; k < spec.values.count; ++k) {
        out << ' ' << spec.values.entries[k].value << ' ' << quoted(spec.values.entries[k].name, signal.name);
      }
      out << " ;\n";
    }
  }
}

}  // namespace
}  // namespace cdcr::firmware::protocol

int main(int argc, char** argv) {
  using cdcr::firmware::protocol::is_valid_id_base;
  const char* usage = "usage: cdcr_write_dbc <out.dbc> [--fd] [--id-base BASE]\n";
  std::uint32_t base = cdcr::firmware::protocol::kDefaultIdBase;
  bool fd = false;
  if (argc < 2) {
    std::cerr << usage;
    return 2;
  }
  for (int i = 2; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--fd") {
      fd = true;
    } else if (option == "--id-base" && i + 1 < argc) {
      const char* text = argv[++i];
      char* end = nullptr;
      const unsigned long value = std::strtoul(text, &end, 0);
      if (end == text || *end != '\0' || value > 0x7FF || !is_valid_id_base(static_cast<std::uint32_t>(value))) {
        std::cerr << "cdcr_write_dbc: error: --id-base must be a multiple of 8 from 0 to 0x780, got '" << text
                  << "'\n";
        return 2;
      }
      base = static_cast<std::uint32_t>(value);
    } else {
      std::cerr << usage;
      return 2;
    }
  }
  const std::string path = argv[1];
  const std::string temporary = path + ".tmp";
  try {
    std::ostringstream text;
    cdcr::firmware::protocol::write_dbc(text, base, fd);
    std::ofstream out(temporary, std::ios::binary);
    out << text.str();
    out.close();
    if (!out) throw std::runtime_error("cannot write " + temporary);
    if (std::rename(temporary.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename it to " + path);
  } catch (const std::exception& error) {
    std::remove(temporary.c_str());
    std::cerr << "cdcr_write_dbc: error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
