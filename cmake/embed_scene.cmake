# Writes OUTPUT (a .cpp) defining `const char* const SYMBOL` with INPUT's text.
file(READ ${INPUT} content)
file(WRITE ${OUTPUT} "namespace tessera {\nextern const char* const ${SYMBOL};\nconst char* const ${SYMBOL} = R\"tessera_scene(${content})tessera_scene\";\n}\n")
