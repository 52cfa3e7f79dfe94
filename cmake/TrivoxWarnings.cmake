# One interface target carries the project's warning, sanitizer and tuning flags, so every
# trivox target gets the same set by linking it.
add_library(trivox_options INTERFACE)
target_compile_options(trivox_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual -Wimplicit-fallthrough)
if(TRIVOX_WERROR)
  target_compile_options(trivox_options INTERFACE -Werror)
endif()
if(TRIVOX_SANITIZE)
  target_compile_options(trivox_options INTERFACE
    -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(trivox_options INTERFACE -fsanitize=address,undefined)
endif()
if(TRIVOX_NATIVE)
  target_compile_options(trivox_options INTERFACE -march=native)
endif()
