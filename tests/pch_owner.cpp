// Translation unit of servotwin_test_pch: the object library that builds the precompiled header all
// test executables reuse (tests/CMakeLists.txt). It compiles nothing of its own.
