# Warnings are errors everywhere in pliant. Targets opt in with pliant_set_warnings(<target>)
# (C++ sources) and pliant_set_c_warnings(<target>) (C99 sources); a mixed target takes both.
set(PLIANT_CXX_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
    -Wdouble-promotion -Wnon-virtual-dtor -Wold-style-cast -Werror)
set(PLIANT_C_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
    -Wdouble-promotion -Wstrict-prototypes -Werror)

function(pliant_set_warnings target)
  target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:CXX>:${PLIANT_CXX_WARNINGS}>")
endfunction()

function(pliant_set_c_warnings target)
  target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:C>:${PLIANT_C_WARNINGS}>")
endfunction()

# Compile options for code that runs on the controller: no exceptions, no RTTI.
function(pliant_set_realtime_flags target)
  target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions;-fno-rtti>")
endfunction()

# Glue code (the tests, the command-line front end) is compiled at -O1 in Release builds: it
# parses options, formats text and calls the libraries, which keep the build type's -O3. This
# takes about a third off these units' compile time (the CLI11 header alone costs a unit several
# seconds of code generation at -O3); the speed that matters is measured by bench/, which keeps -O3.
function(pliant_optimize_for_build_time target)
  target_compile_options(${target} PRIVATE "$<$<CONFIG:Release>:-O1>")
endfunction()
