// The DBC file the build writes from the codec's table (protocol/messages.hpp,
// by firmware/protocol/write_dbc.cpp) describes the table's frames: read back
// with a parser of this test's own, every message and signal of one is in the
// other, with the same identifier, DLC, sender, start bit, length, byte order,
// sign, factor, offset, range, unit and value table. This checks the writer
// and the file's syntax; a wrong start bit or scale in the table itself is
// what protocol_golden_frames_test.cpp catches.

#include <cstdint>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include <cdcr/firmware/fault_detail.hpp>
#include <cdcr/firmware/protocol.hpp>

namespace cdcr::firmware::protocol {
namespace {

using ValueMap = std::map<std::uint32_t, std::string>;

struct DbcSignal {
  int start_bit = 0;
  int length_bits = 0;
  int byte_order = 0;
  bool is_signed = false;
  double factor = 0;
  double offset = 0;
  double minimum = 0;
  double maximum = 0;
  std::string unit;
  std::string receivers;
};

struct DbcMessage {
  std::string name;
  int dlc = 0;
  std::string sender;
  std::map<std::string, DbcSignal> signals;
};

struct Dbc {
  std::set<std::string> nodes;  // BU_
  std::map<std::uint32_t, DbcMessage> messages;
  std::map<std::pair<std::uint32_t, std::string>, ValueMap> value_tables;      // VAL_
  std::map<std::pair<std::uint32_t, std::string>, std::string> signal_notes;  // CM_ SG_
  std::map<std::uint32_t, int> frame_formats;                                  // BA_ "VFrameFormat"
  std::string bus_type;                                                        // BA_ "BusType"
};

ValueMap parse_values(const std::string& text) {
  ValueMap values;
  const std::regex entry(R"re((\d+) "([^"]*)")re");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), entry); it != std::sregex_iterator(); ++it) {
    values[static_cast<std::uint32_t>(std::stoul((*it)[1]))] = (*it)[2];
  }
  return values;
}

Dbc read_dbc(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  const std::regex message(R"re(^BO_ (\d+) (\w+): (\d+) (\w+)\s*$)re");
  const std::regex signal(
      R"re(^ SG_ (\w+) : (\d+)\|(\d+)@([01])([+-]) \(([^,]+),([^)]+)\) \[([^|]+)\|([^\]]+)\] "([^"]*)" (.+)$)re");
  const std::regex nodes(R"re(^BU_:((?: \w+)*)\s*$)re");
  const std::regex value_table(R"re(^VAL_ (\d+) (\w+) ((?:\d+ "[^"]*" )*);\s*$)re");
  const std::regex signal_note(R"re(^CM_ SG_ (\d+) (\w+) "([^"]*)";\s*$)re");
  const std::regex frame_format(R"re(^BA_ "VFrameFormat" BO_ (\d+) (\d+);\s*$)re");
  const std::regex bus_type(R"re(^BA_ "BusType" "([^"]*)";\s*$)re");
  Dbc dbc;
  DbcMessage* current = nullptr;
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, message)) {
      const auto id = static_cast<std::uint32_t>(std::stoul(m[1]));
      EXPECT_EQ(dbc.messages.count(id), 0u) << "identifier listed twice: " << line;
      current = &dbc.messages[id];
      current->name = m[2];
      current->dlc = std::stoi(m[3]);
      current->sender = m[4];
    } else if (std::regex_match(line, m, signal)) {
      EXPECT_NE(current, nullptr) << line;
      if (current == nullptr) continue;
      EXPECT_EQ(current->signals.count(m[1]), 0u) << "signal listed twice: " << line;
      current->signals[m[1]] = DbcSignal{std::stoi(m[2]),  std::stoi(m[3]),  std::stoi(m[4]),
                                         m[5] == "-",      std::stod(m[6]),  std::stod(m[7]),
                                         std::stod(m[8]),  std::stod(m[9]),  m[10],
                                         m[11]};
    } else if (std::regex_match(line, m, nodes)) {
      std::istringstream names(m[1]);
      for (std::string name; names >> name;) dbc.nodes.insert(name);
    } else if (std::regex_match(line, m, value_table)) {
      dbc.value_tables[{static_cast<std::uint32_t>(std::stoul(m[1])), m[2]}] = parse_values(m[3]);
    } else if (std::regex_match(line, m, signal_note)) {
      dbc.signal_notes[{static_cast<std::uint32_t>(std::stoul(m[1])), m[2]}] = m[3];
    } else if (std::regex_match(line, m, frame_format)) {
      dbc.frame_formats[static_cast<std::uint32_t>(std::stoul(m[1]))] = std::stoi(m[2]);
    } else if (std::regex_match(line, m, bus_type)) {
      dbc.bus_type = m[1];
    } else {
      EXPECT_EQ(line.rfind(" SG_", 0), std::string::npos) << "unparsed signal line: " << line;
      EXPECT_EQ(line.rfind("BO_ ", 0), std::string::npos) << "unparsed message line: " << line;
      EXPECT_EQ(line.rfind("VAL_ ", 0), std::string::npos) << "unparsed value table: " << line;
      EXPECT_EQ(line.rfind("CM_ SG_", 0), std::string::npos) << "unparsed signal comment: " << line;
      EXPECT_EQ(line.rfind("BA_ ", 0), std::string::npos) << "unparsed attribute: " << line;
    }
  }
  return dbc;
}

const Dbc& dbc() {
  static const Dbc parsed = read_dbc(CDCR_DBC_PATH);
  return parsed;
}

// The codec's messages by identifier, per-segment ones expanded to the
// <name>_<segment> messages the DBC lists.
struct CodecMessage {
  std::string name;
  const MessageSpec* spec;
};

std::map<std::uint32_t, CodecMessage> codec_messages() {
  std::map<std::uint32_t, CodecMessage> messages;
  for (const MessageSpec* spec : kMessages) {
    for (int i = 0; i < spec->id_count; ++i) {
      const std::string name = spec->id_count == 1 ? spec->name : spec->name + std::string("_") + std::to_string(i);
      EXPECT_TRUE(messages.emplace(spec->id + std::uint32_t(i), CodecMessage{name, spec}).second) << name;
    }
  }
  return messages;
}

ValueMap codec_values(const SignalSpec& signal) {
  ValueMap values;
  for (int i = 0; i < signal.values.count; ++i) values[signal.values.entries[i].value] = signal.values.entries[i].name;
  return values;
}

// With the window moved to 0x300 (cdcr_write_dbc --id-base 0x300): every
// message, signal, value table and comment of the default DBC, each
// identifier 0x200 higher, and nothing else.
TEST(DbcAtAnotherBase, IsTheDefaultShiftedByTheBase) {
  const Dbc shifted = read_dbc(CDCR_DBC_AT_0X300_PATH);
  const Dbc& base = dbc();
  ASSERT_EQ(shifted.messages.size(), base.messages.size());
  for (const auto& [id, message] : base.messages) {
    ASSERT_EQ(shifted.messages.count(id + 0x200), 1u) << message.name;
    const DbcMessage& moved = shifted.messages.at(id + 0x200);
    EXPECT_EQ(moved.name, message.name);
    EXPECT_EQ(moved.dlc, message.dlc);
    EXPECT_EQ(moved.signals.size(), message.signals.size()) << message.name;
  }
  EXPECT_EQ(shifted.messages.begin()->first, 0x300u);
  EXPECT_EQ(shifted.messages.begin()->second.name, "CABLE_FEEDBACK_0");
  ASSERT_EQ(shifted.value_tables.size(), base.value_tables.size());
  for (const auto& [key, values] : base.value_tables) {
    ASSERT_EQ(shifted.value_tables.count({key.first + 0x200, key.second}), 1u) << key.second;
    EXPECT_EQ(shifted.value_tables.at({key.first + 0x200, key.second}), values);
  }
  EXPECT_EQ(shifted.signal_notes.size(), base.signal_notes.size());
}

TEST(IdBase, IsAMultipleOf8WithTheWindowWithinTheIdentifiers) {
  EXPECT_TRUE(is_valid_id_base(kDefaultIdBase));
  EXPECT_TRUE(is_valid_id_base(0x300));
  EXPECT_TRUE(is_valid_id_base(0x000));
  EXPECT_TRUE(is_valid_id_base(0x780));
  EXPECT_FALSE(is_valid_id_base(0x788));  // the window would pass 0x7FF
  EXPECT_FALSE(is_valid_id_base(0x304));
  EXPECT_EQ(id_offset(kDefaultIdBase), 0u);
  EXPECT_EQ(id_offset(0x300), 0x200u);
  EXPECT_EQ(id_offset(0x000), 0x700u);  // -0x100, modulo 2,048
}

TEST(DbcAgreesWithTheCodec, SameMessages) {
  const auto codec = codec_messages();
  for (const auto& [id, message] : codec) EXPECT_EQ(dbc().messages.count(id), 1u) << "not in the DBC: " << message.name;
  for (const auto& [id, message] : dbc().messages) {
    EXPECT_EQ(codec.count(id), 1u) << "not in the codec: " << message.name;
  }
}

TEST(DbcAgreesWithTheCodec, SameMessageHeaders) {
  for (const auto& [id, expected] : codec_messages()) {
    const auto found = dbc().messages.find(id);
    if (found == dbc().messages.end()) continue;  // SameMessages says so
    SCOPED_TRACE(expected.name);
    EXPECT_EQ(found->second.name, expected.name);
    EXPECT_EQ(found->second.dlc, expected.spec->dlc);
    EXPECT_EQ(found->second.sender, expected.spec->sender);
  }
}

TEST(DbcAgreesWithTheCodec, SameSignals) {
  for (const auto& [id, expected] : codec_messages()) {
    const auto found = dbc().messages.find(id);
    if (found == dbc().messages.end()) continue;
    SCOPED_TRACE(expected.name);
    const DbcMessage& message = found->second;
    std::set<std::string> codec_names;
    for (const SignalSpec* s : expected.spec->signals) {
      codec_names.insert(s->name);
      SCOPED_TRACE(s->name);
      const auto sig = message.signals.find(s->name);
      if (sig == message.signals.end()) {
        ADD_FAILURE() << "signal not in the DBC";
        continue;
      }
      EXPECT_EQ(sig->second.start_bit, s->start_bit);
      EXPECT_EQ(sig->second.length_bits, s->length_bits);
      EXPECT_EQ(sig->second.byte_order, kDbcIntelByteOrder);
      EXPECT_EQ(sig->second.is_signed, s->is_signed);
      // Exactly: the DBC's decimal text must read as the codec's double.
      EXPECT_EQ(sig->second.factor, s->factor);
      EXPECT_EQ(sig->second.offset, s->offset);
      EXPECT_EQ(sig->second.minimum, s->minimum);
      EXPECT_EQ(sig->second.maximum, s->maximum);
      EXPECT_EQ(sig->second.unit, s->unit);
    }
    for (const auto& [name, signal] : message.signals) {
      EXPECT_EQ(codec_names.count(name), 1u) << "signal not in the codec: " << name;
    }
  }
}

TEST(DbcAgreesWithTheCodec, SameValueTables) {
  const auto codec = codec_messages();
  std::set<std::pair<std::uint32_t, std::string>> codec_tables;
  for (const auto& [id, expected] : codec) {
    for (const SignalSpec* s : expected.spec->signals) {
      if (s->values.count == 0) continue;
      codec_tables.insert({id, s->name});
      const auto found = dbc().value_tables.find({id, s->name});
      if (found == dbc().value_tables.end()) {
        ADD_FAILURE() << expected.name << "." << s->name << ": no VAL_ in the DBC";
        continue;
      }
      EXPECT_EQ(found->second, codec_values(*s)) << expected.name << "." << s->name;
    }
  }
  for (const auto& [key, values] : dbc().value_tables) {
    EXPECT_EQ(codec_tables.count(key), 1u) << "VAL_ " << key.first << " " << key.second << " has no codec table";
  }
}

// Every sender and receiver is a node the database declares (BU_), and a
// message never goes to its own sender.
TEST(DbcAgreesWithTheCodec, SendersAndReceiversAreDeclaredNodes) {
  EXPECT_FALSE(dbc().nodes.empty()) << "no BU_ line";
  for (const auto& [id, message] : dbc().messages) {
    SCOPED_TRACE(message.name);
    EXPECT_EQ(dbc().nodes.count(message.sender), 1u) << "sender " << message.sender;
    for (const auto& [name, signal] : message.signals) {
      std::istringstream receivers(signal.receivers);
      int count = 0;
      for (std::string receiver; std::getline(receivers, receiver, ',');) {
        EXPECT_EQ(dbc().nodes.count(receiver), 1u) << name << ": receiver " << receiver;
        EXPECT_NE(receiver, message.sender) << name;
        ++count;
      }
      EXPECT_GE(count, 1) << name << " has no receiver";
    }
  }
}

void expect_signal(const DbcSignal& dbc_signal, const SignalSpec& spec, int start_bit) {
  EXPECT_EQ(dbc_signal.start_bit, start_bit);
  EXPECT_EQ(dbc_signal.length_bits, spec.length_bits);
  EXPECT_EQ(dbc_signal.byte_order, kDbcIntelByteOrder);
  EXPECT_EQ(dbc_signal.is_signed, spec.is_signed);
  EXPECT_EQ(dbc_signal.factor, spec.factor);
  EXPECT_EQ(dbc_signal.offset, spec.offset);
  EXPECT_EQ(dbc_signal.minimum, spec.minimum);
  EXPECT_EQ(dbc_signal.maximum, spec.maximum);
  EXPECT_EQ(dbc_signal.unit, spec.unit);
}

const Dbc& fd_dbc() {
  static const Dbc parsed = read_dbc(CDCR_FD_DBC_PATH);
  return parsed;
}

// The classical DBC says nothing of frame formats: a reader takes its
// frames as classical ones.
TEST(FdDbc, TheClassicalDbcHasNoFdAttributes) {
  EXPECT_TRUE(dbc().frame_formats.empty());
  EXPECT_TRUE(dbc().bus_type.empty());
}

// The FD bus's DBC: the classical DBC's messages, each an FD frame
// (VFrameFormat 14, StandardCAN_FD), then the FD messages.
TEST(FdDbc, HoldsEveryClassicalMessageAsAnFdFrame) {
  EXPECT_EQ(fd_dbc().bus_type, "CAN FD");
  for (const auto& [id, message] : dbc().messages) {
    SCOPED_TRACE(message.name);
    ASSERT_EQ(fd_dbc().messages.count(id), 1u);
    const DbcMessage& fd = fd_dbc().messages.at(id);
    EXPECT_EQ(fd.name, message.name);
    EXPECT_EQ(fd.dlc, message.dlc);
    EXPECT_EQ(fd.sender, message.sender);
    ASSERT_EQ(fd.signals.size(), message.signals.size());
    for (const auto& [name, signal] : message.signals) {
      ASSERT_EQ(fd.signals.count(name), 1u) << name;
      EXPECT_EQ(fd.signals.at(name).start_bit, signal.start_bit) << name;
    }
  }
  for (const auto& [id, message] : fd_dbc().messages) {
    EXPECT_EQ(fd_dbc().frame_formats.count(id) ? fd_dbc().frame_formats.at(id) : -1, 14) << message.name;
  }
  EXPECT_EQ(fd_dbc().frame_formats.size(), fd_dbc().messages.size());
}

// Each FD message at each of its identifiers, its length, its sender, and
// part k's signals 64 k bits into the frame under the part's name
// (<MESSAGE>_<SIGNAL>, a per-segment part <MESSAGE>_<k>_<SIGNAL>), with
// the part's value tables.
TEST(FdDbc, DescribesEachFdMessageAsItsPartsAtTheirBytes) {
  std::size_t fd_frames = 0;
  for (const FdMessageSpec* spec : kFdMessages) {
    for (int i = 0; i < spec->id_count; ++i) {
      ++fd_frames;
      const std::string name = spec->id_count == 1 ? spec->name : spec->name + std::string("_") + std::to_string(i);
      SCOPED_TRACE(name);
      const std::uint32_t id = spec->id + std::uint32_t(i);
      ASSERT_EQ(fd_dbc().messages.count(id), 1u);
      const DbcMessage& message = fd_dbc().messages.at(id);
      EXPECT_EQ(message.name, name);
      EXPECT_EQ(message.dlc, spec->length);
      EXPECT_EQ(message.sender, spec->sender);
      std::size_t signals = 0;
      for (int k = 0; k < spec->part_count; ++k) {
        const MessageSpec& part = *spec->parts[k].message;
        const std::string prefix =
            std::string(part.name) + "_" + (part.id_count > 1 ? std::to_string(k) + "_" : std::string());
        for (const SignalSpec* s : part.signals) {
          ++signals;
          SCOPED_TRACE(prefix + s->name);
          const auto found = message.signals.find(prefix + s->name);
          if (found == message.signals.end()) {
            ADD_FAILURE() << "signal not in the FD DBC";
            continue;
          }
          expect_signal(found->second, *s, s->start_bit + 64 * k);
          if (s->values.count > 0) {
            const auto table = fd_dbc().value_tables.find({id, prefix + s->name});
            ASSERT_NE(table, fd_dbc().value_tables.end()) << "no VAL_";
            EXPECT_EQ(table->second, codec_values(*s));
          }
        }
      }
      EXPECT_EQ(message.signals.size(), signals);
    }
  }
  EXPECT_EQ(fd_dbc().messages.size(), dbc().messages.size() + fd_frames);
}

// The FAULT_DETAIL comment says, for every fault code that carries a
// detail, which enum it is (fault_detail.hpp holds the same table).
TEST(DbcAgreesWithTheCodec, FaultDetailCommentNamesTheEnumOfEveryDetailedFault) {
  const auto note = dbc().signal_notes.find({stats::kMessage.id, stats::kFaultDetail.name});
  ASSERT_NE(note, dbc().signal_notes.end()) << "no CM_ SG_ for FAULT_DETAIL";
  // One sentence per group of fault codes.
  std::map<std::string, std::string> sentence_of_fault;
  std::istringstream sentences(note->second);
  std::string sentence;
  while (std::getline(sentences, sentence, '.')) {
    for (const ValueName& fault : values::kFaultCode) {
      const std::string named = std::to_string(fault.value) + " " + fault.name;
      if (sentence.find(named) != std::string::npos) sentence_of_fault[fault.name] = sentence;
    }
  }
  for (const ValueName& fault : values::kFaultCode) {
    SCOPED_TRACE(fault.name);
    switch (detail_kind(static_cast<FaultCode>(fault.value))) {
      case FaultDetailKind::image_status:
        ASSERT_EQ(sentence_of_fault.count(fault.name), 1u);
        EXPECT_NE(sentence_of_fault[fault.name].find("model::ImageStatus"), std::string::npos);
        break;
      case FaultDetailKind::model_status:
        ASSERT_EQ(sentence_of_fault.count(fault.name), 1u);
        EXPECT_NE(sentence_of_fault[fault.name].find("model::Status"), std::string::npos);
        break;
      case FaultDetailKind::drive_node:
        ASSERT_EQ(sentence_of_fault.count(fault.name), 1u);
        EXPECT_NE(sentence_of_fault[fault.name].find("node id"), std::string::npos);
        break;
      case FaultDetailKind::none:
        EXPECT_EQ(sentence_of_fault.count(fault.name), 0u) << "named as carrying a detail";
        break;
    }
  }
}

}  // namespace
}  // namespace cdcr::firmware::protocol
