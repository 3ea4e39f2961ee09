// The allocation hooks behind allocation_counter.hpp.

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>

#include "allocation_counter.hpp"

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* pointer);
}

namespace {

std::atomic<bool> g_counting{false};
std::atomic<long> g_operator_new_calls{0};
std::atomic<long> g_malloc_calls{0};

void note(std::atomic<long>& counter) {
  if (g_counting.load(std::memory_order_relaxed)) counter.fetch_add(1, std::memory_order_relaxed);
}

void* checked_new(std::size_t size) {
  note(g_operator_new_calls);
  if (void* pointer = __libc_malloc(size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}

void* checked_aligned_new(std::size_t size, std::align_val_t alignment) {
  note(g_operator_new_calls);
  if (void* pointer = __libc_memalign(static_cast<std::size_t>(alignment), size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}

void* nothrow_new(std::size_t size) noexcept {
  note(g_operator_new_calls);
  return __libc_malloc(size == 0 ? 1 : size);
}

void* nothrow_aligned_new(std::size_t size, std::align_val_t alignment) noexcept {
  note(g_operator_new_calls);
  return __libc_memalign(static_cast<std::size_t>(alignment), size == 0 ? 1 : size);
}

}  // namespace

extern "C" {
void* malloc(std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_realloc(pointer, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  note(g_malloc_calls);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  note(g_malloc_calls);
  if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* pointer = __libc_memalign(alignment, size);
  if (pointer == nullptr) return ENOMEM;
  *out = pointer;
  return 0;
}
void free(void* pointer) noexcept { __libc_free(pointer); }
}

void* operator new(std::size_t size) { return checked_new(size); }
void* operator new[](std::size_t size) { return checked_new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return nothrow_new(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return nothrow_new(size); }
void* operator new(std::size_t size, std::align_val_t alignment) { return checked_aligned_new(size, alignment); }
void* operator new[](std::size_t size, std::align_val_t alignment) { return checked_aligned_new(size, alignment); }
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return nothrow_aligned_new(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return nothrow_aligned_new(size, alignment);
}
void operator delete(void* pointer) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::size_t) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::size_t) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, const std::nothrow_t&) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, const std::nothrow_t&) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::size_t, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::size_t, std::align_val_t) noexcept { __libc_free(pointer); }
void operator delete(void* pointer, std::align_val_t, const std::nothrow_t&) noexcept { __libc_free(pointer); }
void operator delete[](void* pointer, std::align_val_t, const std::nothrow_t&) noexcept { __libc_free(pointer); }

namespace cdcr::test_support {

long allocation_count_operator_new() { return g_operator_new_calls.load(); }
long allocation_count_malloc() { return g_malloc_calls.load(); }
void allocation_counting(bool enabled) {
  if (enabled) {
    g_operator_new_calls.store(0);
    g_malloc_calls.store(0);
  }
  g_counting.store(enabled);
}

}  // namespace cdcr::test_support
