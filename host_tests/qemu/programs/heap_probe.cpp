// Must not link: proves the heap guard of hal/cortexm (ctest
// qemu.link_guard_*). Built only on request.
#include <cstdlib>

int main() {
  void* volatile block = std::malloc(16);
  return block == nullptr ? 1 : 0;
}
