#pragma once
// Counts heap allocations of the whole process while a counter is alive.
// Link allocation_hooks.cpp into the test executable: it replaces the global
// operator new/delete family and interposes malloc, calloc, realloc,
// aligned_alloc and posix_memalign, forwarding to glibc's own entry points.
// Only allocations made while an AllocationCounter is alive are counted, so
// gtest's bookkeeping outside the measured regions does not count; make
// assertions after stop(). One executable per allocation test.

namespace cdcr::test_support {

long allocation_count_operator_new();
long allocation_count_malloc();
void allocation_counting(bool enabled);  // also resets the counts when enabling

class AllocationCounter {
 public:
  AllocationCounter() { allocation_counting(true); }
  ~AllocationCounter() { stop(); }
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;

  void stop() { allocation_counting(false); }
  long operator_new_calls() const { return allocation_count_operator_new(); }
  long malloc_calls() const { return allocation_count_malloc(); }
};

}  // namespace cdcr::test_support
