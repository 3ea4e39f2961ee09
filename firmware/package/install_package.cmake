# The installed package: `cmake --install <build> --prefix <prefix>` puts
#   include/cdcr/...                       the C header cdcr/cdcr.h and the C++ headers
#   lib/libcdcr_c_api.a, libcdcr_firmware.a, libcdcr_callbacks.a
#   lib/cdcr/...                           (cross builds) the MPS2 board's startup objects
#   lib/cmake/cdcr/cdcrConfig.cmake, ...   the package find_package(cdcr) reads
#   share/cdcr/toolchains/*                the toolchain files a cross consumer configures with
#   share/cdcr/mps2.ld                     (cross builds) the MPS2 boards' linker script
# Each target installs itself where it is defined (install(TARGETS ...
# EXPORT cdcrTargets)); this file writes the package around them.
include(CMakePackageConfigHelpers)

set(CDCR_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/cdcr)

install(EXPORT cdcrTargets NAMESPACE cdcr:: DESTINATION ${CDCR_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/cdcrConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/cdcrConfig.cmake INSTALL_DESTINATION ${CDCR_INSTALL_CMAKEDIR})
# The version check also compares the pointer size, so a host consumer
# skips a Cortex-M prefix and the other way round.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/cdcrConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/cdcrConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/cdcrConfigVersion.cmake
  DESTINATION ${CDCR_INSTALL_CMAKEDIR})
install(FILES
  ${PROJECT_SOURCE_DIR}/toolchains/arm-none-eabi-common.cmake
  ${PROJECT_SOURCE_DIR}/toolchains/arm-none-eabi-cortex-m7.cmake
  ${PROJECT_SOURCE_DIR}/toolchains/arm-none-eabi-cortex-m4f.cmake
  ${PROJECT_SOURCE_DIR}/toolchains/bare_metal_eigen_config.hpp
  DESTINATION ${CMAKE_INSTALL_DATADIR}/cdcr/toolchains)
