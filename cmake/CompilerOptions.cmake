# SPDX-License-Identifier: BSD-3-Clause
# radargauss_configure_target(<target>): the one place that sets the language
# standard, the warnings and (with RADARGAUSS_SANITIZE) the sanitizers for
# every target of the project.
#
# No -march=native: Debian's Ceres and PCL are built for generic x86-64 and
# mixing Eigen alignment assumptions with them crashes (docs/design.md, "Dependencies and pitfalls").
function(radargauss_configure_target target)
  target_compile_features(${target} PUBLIC cxx_std_17)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic>)
  if(RADARGAUSS_SANITIZE)
    target_compile_options(${target} PRIVATE
      -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined,float-cast-overflow)
  endif()
endfunction()
