#pragma once
// Stack high-water mark: fill the unused stack with a pattern early, read
// how deep the pattern was overwritten later. This is how the stack
// reservation in the linker script is sized against real use.

#include <cstddef>
#include <cstdint>

extern "C" {
extern std::uint32_t __stack_bottom__[];
extern std::uint32_t __stack_top__[];
}

namespace cdcr::cortexm {

inline constexpr std::uint32_t kStackPaint = 0x5AC3A55Au;

// Paints from the bottom of the stack to a little below the caller's frame.
__attribute__((noinline)) inline void paint_stack() {
  auto* const limit = static_cast<std::uint32_t*>(__builtin_frame_address(0)) - 64;
  for (std::uint32_t* word = __stack_bottom__; word < limit; ++word) *word = kStackPaint;
  asm volatile("" ::: "memory");
}

inline std::size_t stack_reserved_bytes() {
  return static_cast<std::size_t>(__stack_top__ - __stack_bottom__) * sizeof(std::uint32_t);
}

inline std::size_t stack_used_bytes() {
  const std::uint32_t* word = __stack_bottom__;
  while (word < __stack_top__ && *word == kStackPaint) ++word;
  return static_cast<std::size_t>(__stack_top__ - word) * sizeof(std::uint32_t);
}

}  // namespace cdcr::cortexm
