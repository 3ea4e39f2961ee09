#pragma once
// The base of every HAL interface. A backend object lives for the whole
// program (statically allocated) and the runtime uses it through a
// reference: it is never deleted, copied or assigned through an interface.
// So the destructors are protected and not virtual: a virtual destructor
// would reference operator delete, and with it the heap, in bare-metal
// builds. Each interface also declares its own destructor protected, so
// that deleting through it does not compile.

namespace cdcr::hal {

class Interface {
 protected:
  Interface() = default;
  ~Interface() = default;
  Interface(const Interface&) = default;
  Interface& operator=(const Interface&) = default;
};

}  // namespace cdcr::hal
