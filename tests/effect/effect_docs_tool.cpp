// flurry_effect_docs schema|reference|dict [--check FILE]: prints a file generated from the
// action descriptors, or with --check compares it with the committed FILE and fails (saying
// how to regenerate it) when they differ. The effect.generated.* tests run the checks.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "effect/effect_docs.hpp"

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  std::string text;
  if (what == "schema")
    text = flurry::detail::effectSchema();
  else if (what == "reference")
    text = flurry::detail::effectReference();
  else if (what == "dict")
    text = flurry::detail::fuzzDictionary();
  else {
    std::fprintf(stderr, "usage: flurry_effect_docs schema|reference|dict [--check FILE]\n");
    return 2;
  }
  if (argc == 4 && std::strcmp(argv[2], "--check") == 0) {
    std::ifstream in(argv[3], std::ios::binary);
    std::stringstream committed;
    committed << in.rdbuf();
    if (in && committed.str() == text) return 0;
    std::fprintf(stderr,
                 "%s is not what the descriptors generate (sdk/src/effect/descriptors.hpp).\n"
                 "Regenerate it with:\n  %s %s > %s\n",
                 argv[3], argv[0], what.c_str(), argv[3]);
    return 1;
  }
  std::cout << text;
  return std::cout ? 0 : 1;
}
