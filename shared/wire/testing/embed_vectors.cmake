# Turns the golden vector file into a header (a raw string literal), at build time, so the test
# image carries the vectors on targets without a file system.
file(READ ${INPUT} text)
file(WRITE ${OUTPUT}.tmp "// Generated from ${INPUT}; do not edit.\n#pragma once\n"
     "namespace vibid::wire::testing {\n"
     "inline constexpr char kWireVectorsText[] = R\"vectors(${text})vectors\";\n}\n")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
