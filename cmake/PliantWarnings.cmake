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
