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
if(SERVOTWIN_SANITIZE)
  target_compile_options(servotwin_build_flags INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(servotwin_build_flags INTERFACE -fsanitize=address,undefined)
endif()
install(TARGETS servotwin_build_flags EXPORT servotwinTargets)
