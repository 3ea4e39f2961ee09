// The translation unit the tests' precompiled header is made from
// (host_tests/CMakeLists.txt, cdcr_test_pch); it has no code of its own.
