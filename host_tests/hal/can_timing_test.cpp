// A frame's time on the wire (hal/can_timing.hpp) against frames written out
// bit by bit: each literal below is the frame from SOF to the end of its
// dynamically stuffed part as a transmitter sends it, stuff bits in
// brackets. The classical CRCs in them were worked by polynomial long
// division (x^15 + x^14 + x^10 + x^8 + x^7 + x^4 + x^3 + 1) over the unstuffed
// bits; the worst cases are the Linux kernel's table (include/linux/can/
// length.h: 111 and 135 bits for a classical 8-byte frame, 579 and 712 for
// a 64-byte FD frame, intermission included).
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cdcr/hal/can_timing.hpp>

namespace cdcr::hal {
namespace {

struct Written {
  std::string frame_bits;  // unstuffed, in order
  std::uint32_t stuff = 0;
};

// "0001[1]0..." -> the frame's bits and the count of bracketed stuff bits.
Written read_written(const std::string& text) {
  Written w;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '[') {
      ++w.stuff;
      i += 2;  // the stuff bit and ']'
    } else {
      w.frame_bits += text[i];
    }
  }
  return w;
}

std::uint32_t field(const std::string& bits, std::size_t first, std::size_t count) {
  return static_cast<std::uint32_t>(std::stoul(bits.substr(first, count), nullptr, 2));
}

constexpr std::uint32_t kTrailer = 13;  // CRC delimiter, ACK slot and delimiter, EOF, intermission

TEST(CanFrameBits, TheClassicalCrcIsTheCataloguesCrc15) {
  // CRC-15/CAN's check value: the CRC of the ASCII bytes "123456789".
  detail::StuffCounter counter;
  for (const char c : std::string("123456789")) {
    for (int i = 7; i >= 0; --i) counter.crc_and_put(((c >> i) & 1) != 0);
  }
  EXPECT_EQ(counter.crc(), 0x059E);
}

struct ClassicalCase {
  std::uint32_t id;
  std::vector<std::uint8_t> data;
  const char* written;
};

TEST(CanFrameBits, ClassicalFramesCountTheStuffBitsTheirContentNeeds) {
  const ClassicalCase cases[] = {
      // All dominant: a stuff bit after every five, CRC 0.
      {0x000, {}, "00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]0000"},
      // Eight zero bytes at the protocol's base identifier; CRC 0x34A8.
      {0x100,
       {0, 0, 0, 0, 0, 0, 0, 0},
       "000100000[1]00000[1]0100000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]"
       "00000[1]00000[1]00000[1]00011010010101000"},
      // Runs of ones and zeros of every length; CRC 0x6BD6.
      {0x17F,
       {0xFF, 0xFF, 0x00, 0x01, 0x7F, 0x80, 0x55, 0xAA},
       "0001011111[0]11000100011111[0]11111[0]11111[0]100000[1]00000[1]00000[1]1011111[0]11100000[1]"
       "000101010110101010110101111010110"},
      // One stuff bit only; CRC 0x36B7.
      {0x123, {0x12, 0x34}, "00010010001100000[1]100001001000110100011011010110111"},
  };
  for (const ClassicalCase& c : cases) {
    const Written w = read_written(c.written);
    // The literal is this frame: SOF, identifier, RTR/IDE/r0, DLC, data, CRC.
    ASSERT_EQ(w.frame_bits.size(), 1 + 11 + 3 + 4 + 8 * c.data.size() + 15) << c.written;
    ASSERT_EQ(field(w.frame_bits, 1, 11), c.id);
    ASSERT_EQ(field(w.frame_bits, 15, 4), c.data.size());
    for (std::size_t i = 0; i < c.data.size(); ++i) ASSERT_EQ(field(w.frame_bits, 19 + 8 * i, 8), c.data[i]);

    const CanFrameBits bits = can_frame_bits(c.id, c.data.data(), c.data.size(), CanFormat::classical);
    EXPECT_EQ(bits.stuff, w.stuff) << std::hex << c.id;
    EXPECT_EQ(bits.nominal, w.frame_bits.size() + w.stuff + kTrailer) << std::hex << c.id;
    EXPECT_EQ(bits.data, 0u);
  }
}

struct FdCase {
  std::uint32_t id;
  std::vector<std::uint8_t> data;
  CanFormat format;
  const char* written;      // SOF to the end of the data
  std::uint32_t arbitration_stuff;  // of the bracketed, those before the bit-rate switch
};

// The CRC field after the data: a fixed stuff bit, the stuff count (4), the
// CRC (17 or 21) and a fixed stuff bit after every fourth bit of the field.
std::uint32_t crc_field_bits(std::size_t length) { return length <= 16 ? 4 + 17 + 6 : 4 + 21 + 7; }

TEST(CanFrameBits, FdFramesStuffTheirDataAndSwitchTheirRateAtBrs) {
  std::vector<std::uint8_t> counting(64);
  for (std::size_t i = 0; i < counting.size(); ++i) counting[i] = static_cast<std::uint8_t>(i);
  const FdCase cases[] = {
      {0x100,
       {0, 0, 0, 0, 0, 0, 0, 0},
       CanFormat::fd_bit_rate_switch,
       "000100000[1]00000[1]1010100000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]00000[1]"
       "00000[1]00000[1]00000[1]00000[1]00",
       2},
      // Twelve bytes (DLC 9) of ones.
      {0x17F,
       std::vector<std::uint8_t>(12, 0xFF),
       CanFormat::fd_bit_rate_switch,
       "0001011111[0]1100101010011111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]"
       "11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11111[0]11",
       1},
      // No data: the five dominant bits of ESI and DLC end the stuffed part
      // and take the CRC field's fixed stuff bit, not a dynamic one.
      {0x100, {}, CanFormat::fd_bit_rate_switch, "000100000[1]00000[1]10100000", 2},
      // 64 bytes (DLC 15, CRC-21), all at the nominal rate.
      {0x055,
       counting,
       CanFormat::fd,
       "00000[1]1010101001000111100000[1]00000[1]00000[1]100000[1]0100000[1]001100000[1]100000[1]0010100000[1]"
       "1100000[1]01110000100000[1]001001000010100000[1]101100001100000[1]01101000011100000[1]1111[0]000100000[1]"
       "0010001000100100001001100010100000[1]1010100010110000101110001100000[1]011001000110100001101100011100000[1]"
       "111010001111000011111[0]00100000[1]001000010010001000100011001001000010010100100110001001110010100000[1]"
       "101001001010100010101100101100001011010010111000101111001100000[1]0110001001100100011001100110100001101010"
       "0110110001101110011100000[1]111001001110100011101100111100001111010011111[0]00011111[0]1",
       1},
  };
  for (const FdCase& c : cases) {
    const Written w = read_written(c.written);
    ASSERT_EQ(w.frame_bits.size(), 17 + 5 + 8 * c.data.size()) << c.written;
    ASSERT_EQ(field(w.frame_bits, 1, 11), c.id);
    ASSERT_EQ(field(w.frame_bits, 12, 5), c.format == CanFormat::fd_bit_rate_switch ? 0b00101u : 0b00100u);
    ASSERT_EQ(field(w.frame_bits, 18, 4), fd_length_code(c.data.size()));
    for (std::size_t i = 0; i < c.data.size(); ++i) ASSERT_EQ(field(w.frame_bits, 22 + 8 * i, 8), c.data[i]);

    const CanFrameBits bits = can_frame_bits(c.id, c.data.data(), c.data.size(), c.format);
    const std::uint32_t arbitration = 17 + c.arbitration_stuff + kTrailer;
    const std::uint32_t data_phase =
        5 + 8 * static_cast<std::uint32_t>(c.data.size()) + (w.stuff - c.arbitration_stuff) + crc_field_bits(c.data.size());
    EXPECT_EQ(bits.stuff, w.stuff) << std::hex << c.id;
    if (c.format == CanFormat::fd_bit_rate_switch) {
      EXPECT_EQ(bits.nominal, arbitration) << std::hex << c.id;
      EXPECT_EQ(bits.data, data_phase) << std::hex << c.id;
    } else {
      EXPECT_EQ(bits.nominal, arbitration + data_phase) << std::hex << c.id;
      EXPECT_EQ(bits.data, 0u);
    }
  }
}

TEST(CanFrameBits, TheWorstCasesAreTheKernelsTable) {
  EXPECT_EQ(can_frame_bits_worst_case(8, CanFormat::classical).total(), 135u);
  EXPECT_EQ(can_frame_bits_worst_case(8, CanFormat::classical).total() -
                can_frame_bits_worst_case(8, CanFormat::classical).stuff,
            111u);
  EXPECT_EQ(can_frame_bits_worst_case(64, CanFormat::fd).total(), 712u);
  EXPECT_EQ(can_frame_bits_worst_case(64, CanFormat::fd).total() - can_frame_bits_worst_case(64, CanFormat::fd).stuff,
            579u);
  // Switching the rate moves bits, it adds none.
  const CanFrameBits fast = can_frame_bits_worst_case(64, CanFormat::fd_bit_rate_switch);
  EXPECT_EQ(fast.total(), 712u);
  EXPECT_EQ(fast.nominal, 17u + 4u + kTrailer);
}

TEST(CanFrameBits, WithoutStuffingIsTheWorstCaseLessItsStuffBits) {
  EXPECT_EQ(can_frame_bits_without_stuffing(8, CanFormat::classical).total(), 111u);
  EXPECT_EQ(can_frame_bits_without_stuffing(64, CanFormat::fd).total(), 579u);
  const CanFrameBits fast = can_frame_bits_without_stuffing(64, CanFormat::fd_bit_rate_switch);
  EXPECT_EQ(fast.nominal, 17u + kTrailer);
  EXPECT_EQ(fast.total(), 579u);
}

TEST(CanFrameBits, NoContentTakesMoreThanTheWorstCase) {
  // Every one-byte payload and a spread of identifiers, both formats.
  for (std::uint32_t id = 0; id <= 0x7FF; id += 0x3B) {
    for (int value = 0; value < 256; ++value) {
      const std::uint8_t byte = static_cast<std::uint8_t>(value);
      for (const CanFormat format : {CanFormat::classical, CanFormat::fd_bit_rate_switch}) {
        const CanFrameBits bits = can_frame_bits(id, &byte, 1, format);
        const CanFrameBits worst = can_frame_bits_worst_case(1, format);
        ASSERT_LE(bits.total(), worst.total());
        ASSERT_LE(bits.nominal, worst.nominal);
        ASSERT_GE(bits.total(), can_frame_bits_without_stuffing(1, format).total());
      }
    }
  }
}

TEST(CanFrameBits, FdLengthsAndTheirCodes) {
  const std::size_t lengths[] = {0, 1, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  const std::uint8_t codes[] = {0, 1, 7, 8, 9, 10, 11, 12, 13, 14, 15};
  for (std::size_t i = 0; i < std::size(lengths); ++i) {
    EXPECT_TRUE(is_fd_length(lengths[i]));
    EXPECT_EQ(fd_length_code(lengths[i]), codes[i]);
    EXPECT_EQ(fd_length_for(lengths[i]), lengths[i]);
  }
  EXPECT_FALSE(is_fd_length(9));
  EXPECT_FALSE(is_fd_length(33));
  EXPECT_FALSE(is_fd_length(65));
  EXPECT_EQ(fd_length_for(9), 12u);
  EXPECT_EQ(fd_length_for(25), 32u);
  EXPECT_EQ(fd_length_for(49), 64u);
}

TEST(CanFrameTime, IsTheBitsAtTheirRatesRoundedUp) {
  CanFrameBits classical;
  classical.nominal = 111;
  EXPECT_EQ(can_frame_time_ns(classical, {1000000, 0}), 111000);
  EXPECT_EQ(can_frame_time_ns(classical, {500000, 0}), 222000);
  CanFrameBits fd;
  fd.nominal = 30;
  fd.data = 100;
  EXPECT_EQ(can_frame_time_ns(fd, {1000000, 5000000}), 30000 + 20000);
  EXPECT_EQ(can_frame_time_ns(fd, {1000000, 3000000}), 30000 + 33334);  // 33,333.3 up
  EXPECT_EQ(can_frame_time_ns(fd, {1000000, 0}), 0);                    // no data rate: not a bus for it
}

}  // namespace
}  // namespace cdcr::hal
