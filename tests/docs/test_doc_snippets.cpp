// The code blocks of README.md, docs/guide.md and docs/c-api.md are the files under docs/snippets/,
// byte for byte: a ```cpp block names its file on its first line (`// docs/snippets/NAME.cpp...`),
// a
// ```json block on the line before its fence (`<!-- docs/snippets/NAME.json -->`). The files
// themselves are built and run as tests (tests/docs/CMakeLists.txt), so a snippet that drifts
// from its file, or a file that stops compiling or doing what the text says, fails.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

const std::filesystem::path kRoot = FLURRY_SOURCE_DIR;

std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Block {
  std::string language, file, body;  // file: the snippet it names, "" if none
  int line = 0;                      // of the opening fence, 1-based
};

std::vector<Block> codeBlocks(const std::string& markdown) {
  std::vector<std::string> lines;
  std::istringstream in(markdown);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::vector<Block> blocks;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].rfind("```", 0) != 0) continue;
    Block b{lines[i].substr(3), "", "", int(i) + 1};
    std::size_t j = i + 1;
    for (; j < lines.size() && lines[j] != "```"; ++j) b.body += lines[j] + "\n";
    const std::string prefix = "// docs/snippets/";
    if ((b.language == "cpp" || b.language == "c") && b.body.rfind(prefix, 0) == 0) {
      std::string first = b.body.substr(3, b.body.find('\n') - 3);
      b.file = first.substr(0, first.find_first_of(": "));
    }
    const std::string open = "<!-- docs/snippets/", close = " -->";
    if (b.language == "json" && i > 0 && lines[i - 1].rfind(open, 0) == 0 &&
        lines[i - 1].size() > open.size() + close.size())
      b.file = lines[i - 1].substr(5, lines[i - 1].size() - 5 - close.size());
    blocks.push_back(b);
    i = j;
  }
  return blocks;
}

// The pages whose C, C++ and JSON blocks must all be snippet files.
const char* const kPages[] = {"README.md", "docs/guide.md", "docs/c-api.md"};

TEST(DocSnippets, EveryCppAndJsonBlockIsItsSnippetFile) {
  for (const char* page : kPages) {
    for (const Block& b : codeBlocks(readText(kRoot / page))) {
      if (b.language != "cpp" && b.language != "c" && b.language != "json") continue;
      SCOPED_TRACE(std::string(page) + ":" + std::to_string(b.line));
      ASSERT_FALSE(b.file.empty())
          << "a ```" << b.language << " block names no docs/snippets/ file (see "
          << "tests/docs/test_doc_snippets.cpp)";
      ASSERT_TRUE(std::filesystem::exists(kRoot / b.file)) << b.file << " does not exist";
      EXPECT_EQ(b.body, readText(kRoot / b.file))
          << "the block differs from " << b.file << ": copy the file into the page";
    }
  }
}

TEST(DocSnippets, EverySnippetFileIsShown) {
  std::set<std::string> shown;
  for (const char* page : kPages)
    for (const Block& b : codeBlocks(readText(kRoot / page)))
      if (!b.file.empty()) shown.insert(b.file);
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(kRoot / "docs/snippets")) {
    std::string name = "docs/snippets/" + e.path().filename().string();
    ++files;
    EXPECT_TRUE(shown.count(name)) << name << " is in no page: show it or remove it";
  }
  EXPECT_GT(files, 0u);
}

// The checker itself: a drifted block, a block without a name, and the json marker.
TEST(DocSnippets, CheckerFindsNamesAndBodies) {
  auto blocks = codeBlocks(
      "text\n```cpp\n// docs/snippets/a.cpp: x\nint i;\n```\n```cpp\nint j;\n```\n"
      "<!-- docs/snippets/b.json -->\n```json\n{}\n```\n```sh\nls\n```\n");
  ASSERT_EQ(blocks.size(), 4u);
  EXPECT_EQ(blocks[0].file, "docs/snippets/a.cpp");
  EXPECT_EQ(blocks[0].body, "// docs/snippets/a.cpp: x\nint i;\n");
  EXPECT_EQ(blocks[0].line, 2);
  EXPECT_EQ(blocks[1].file, "");
  EXPECT_EQ(blocks[2].file, "docs/snippets/b.json");
  EXPECT_EQ(blocks[2].body, "{}\n");
  EXPECT_EQ(blocks[3].language, "sh");
}

}  // namespace
