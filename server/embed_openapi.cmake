# Writes OUTPUT, a C++ file defining zebrageo::OpenApiDocument() as the
# text of INPUT (server/openapi.json).
file(READ "${INPUT}" text)
set(delimiter "zebrageo_openapi")
file(WRITE "${OUTPUT}.tmp"
  "// Generated from server/openapi.json by embed_openapi.cmake.\n"
  "#include \"server/server.h\"\n\n"
  "namespace zebrageo {\n\n"
  "const std::string& OpenApiDocument() {\n"
  "  static const std::string kDocument = R\"${delimiter}(${text})${delimiter}\";\n"
  "  return kDocument;\n"
  "}\n\n"
  "}  // namespace zebrageo\n")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
