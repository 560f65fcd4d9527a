# Warning and sanitizer flags shared by every target of the project.
add_library(servotwin_build_flags INTERFACE)
target_compile_options(servotwin_build_flags INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
    -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion
    -Wimplicit-fallthrough>)
if(SERVOTWIN_WERROR)
  target_compile_options(servotwin_build_flags INTERFACE -Werror)
endif()
if(SERVOTWIN_SANITIZE)
  target_compile_options(servotwin_build_flags INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(servotwin_build_flags INTERFACE -fsanitize=address,undefined)
endif()
install(TARGETS servotwin_build_flags EXPORT servotwinTargets)
