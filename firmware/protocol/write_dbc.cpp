// Writes the protocol's DBC file from the codec's table
// (cdcr/firmware/protocol/messages.hpp), so that candump and cantools users
// decode exactly the frames the runtime packs. The build runs it; nobody
// edits its output.
//
// Usage: cdcr_write_dbc <out.dbc> [--id-base BASE]
//
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

void write_signal(std::ostream& out, const SignalSpec& signal, const char* receiver) {
  out << " SG_ " << signal.name << " : " << int(signal.start_bit) << '|' << int(signal.length_bits) << '@'
      << kDbcIntelByteOrder << (signal.is_signed ? '-' : '+') << " (" << dbc_number(signal.factor) << ','
      << dbc_number(signal.offset) << ") [" << dbc_number(signal.minimum) << '|' << dbc_number(signal.maximum)
      << "] " << quoted(signal.unit, signal.name) << ' ' << receiver << '\n';
}

void write_dbc(std::ostream& out, std::uint32_t base) {
  const std::uint32_t shift = id_offset(base);
  const auto on_bus = [shift](std::uint32_t id) { return hal::ShiftedCanBus::shifted(id, shift); };
  out << "VERSION " << quoted(kDbcVersion, "VERSION") << "\n\n";
  out << "NS_ :\n\nBS_:\n\nBU_:";
  for (const char* node : kDbcNodes) out << ' ' << node;
  out << "\n\n";

  for (const MessageNotes* notes : kMessageNotes) {
    check_notes(*notes);
    const MessageSpec* message = notes->message;
    for (int i = 0; i < message->id_count; ++i) {
      out << "BO_ " << on_bus(message->id + i) << ' ' << frame_name(*message, i) << ": " << int(message->dlc) << ' '
          << message->sender << '\n';
      for (const SignalSpec* signal : message->signals) write_signal(out, *signal, notes->receiver);
      out << '\n';
    }
  }

  out << "CM_ " << quoted(kDbcComment, "the database comment") << ";\n";
  for (const MessageNotes* notes : kMessageNotes) {
    const MessageSpec* message = notes->message;
    for (int i = 0; i < message->id_count; ++i) {
      const std::uint32_t id = on_bus(message->id + i);
      const std::string name = frame_name(*message, i);
      if (*notes->comment != '\0') {
        out << "CM_ BO_ " << id << ' ' << quoted(with_segment(notes->comment, i), name) << ";\n";
      }
      // In the signals' order, whatever the order of the notes.
      for (const SignalSpec* signal : message->signals) {
        for (const SignalNote& note : notes->signals) {
          if (note.signal != signal) continue;
          out << "CM_ SG_ " << id << ' ' << signal->name << ' ' << quoted(note.text, name + "." + signal->name)
              << ";\n";
        }
      }
    }
  }

  for (const MessageSpec* message : kMessages) {
    for (int i = 0; i < message->id_count; ++i) {
      for (const SignalSpec* signal : message->signals) {
        if (signal->values.count == 0) continue;
        out << "VAL_ " << on_bus(message->id + i) << ' ' << signal->name;
        for (int k = 0; k < signal->values.count; ++k) {
          out << ' ' << signal->values.entries[k].value << ' '
              << quoted(signal->values.entries[k].name, signal->name);
        }
        out << " ;\n";
      }
    }
  }
}

}  // namespace
}  // namespace cdcr::firmware::protocol

int main(int argc, char** argv) {
  using cdcr::firmware::protocol::is_valid_id_base;
  std::uint32_t base = cdcr::firmware::protocol::kDefaultIdBase;
  const bool with_base = argc == 4 && std::string(argv[2]) == "--id-base";
  if (argc != 2 && !with_base) {
    std::cerr << "usage: cdcr_write_dbc <out.dbc> [--id-base BASE]\n";
    return 2;
  }
  if (with_base) {
    char* end = nullptr;
    const unsigned long value = std::strtoul(argv[3], &end, 0);
    if (end == argv[3] || *end != '\0' || value > 0x7FF || !is_valid_id_base(static_cast<std::uint32_t>(value))) {
      std::cerr << "cdcr_write_dbc: error: --id-base must be a multiple of 8 from 0 to 0x780, got '" << argv[3]
                << "'\n";
      return 2;
    }
    base = static_cast<std::uint32_t>(value);
  }
  const std::string path = argv[1];
  const std::string temporary = path + ".tmp";
  try {
    std::ostringstream text;
    cdcr::firmware::protocol::write_dbc(text, base);
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
