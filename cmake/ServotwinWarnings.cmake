# Warning and sanitizer flags shared by every target of the project.
add_library(servotwin_build_flags INTERFACE)
target_compile_options(servotwin_build_flags INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
    -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion
    -Wimplicit-fallthrough>)
# GCC 12 reports false -Wrestrict errors inside std::string's operator+ at -O2 (GCC bugs 105329,
# 105651): silence that one warning on GCC < 13 rather than contort string code.
target_compile_options(servotwin_build_flags INTERFACE
  $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-restrict>)
if(SERVOTWIN_WERROR)
  target_compile_options(servotwin_build_flags INTERFACE -Werror)
endif()
# The sanitizer pass must fit CI's 50-minute budget beside the release pass, so its compile time
# is spent where it finds defects (times below: one file, compiled beside another as the build does):
# * Product code (libraries, CLI): address + undefined, without UBSan's alignment, null and vptr
#   checks. Those instrument every Eigen element access and member call (core/model_reduction.cpp:
#   77 s with them, 70 s without, 48 s with address alone) and add little here: a null
#   dereference faults and ASan reports it with its stack; x86 tolerates misalignment and the code
#   does no type punning; vptr needs a wrong downcast of a polymorphic type.
# * Test executables (SERVOTWIN_TEST_SANITIZER_OPTIONS): address only. Their memory errors are
#   caught (last found: a dangling reference in a test) and the library's own functions keep
#   their UBSan checks; their one-per-module translation units compile in 80 % of the time (the
#   tuning tests: 181 s, 147 s). Not -O0: the linker keeps one copy of each template instance, often
#   the test's, and Eigen at -O0 made the tuning tests five times slower.
if(SERVOTWIN_SANITIZE)
  target_compile_options(servotwin_build_flags INTERFACE -fsanitize=address,undefined -fno-sanitize=alignment,null,vptr
                         -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(servotwin_build_flags INTERFACE -fsanitize=address,undefined)
  set(SERVOTWIN_TEST_SANITIZER_OPTIONS -fno-sanitize=undefined)
else()
  set(SERVOTWIN_TEST_SANITIZER_OPTIONS)
endif()
install(TARGETS servotwin_build_flags EXPORT servotwinTargets)
