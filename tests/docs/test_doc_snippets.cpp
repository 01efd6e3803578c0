// The code blocks of README.md, docs/guide.md and docs/c-api.md are the files under docs/snippets/,
// byte for byte: a ```cpp block names its file on its first line (`// docs/snippets/NAME.cpp...`),
// a
// ```json block on the line before its fence (`<!-- docs/snippets/NAME.json -->`). The files
// themselves are built and run as tests (tests/docs/CMakeLists.txt), so a snippet that drifts
// from its file, or a file that stops compiling or doing what the text says, fails.
#include <gtest/gtest.h>

#include <cctype>
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

// ---- docs/adding-an-action.md -----------------------------------------------------------------
// The page walks through a real action by its files and names rather than by code blocks:
// every path and every name in its `code spans` must exist in the sources, so that a rename
// or a move fails here instead of leaving the page wrong.

/// The `spans` of a page outside its fenced blocks.
std::vector<std::string> codeSpans(const std::string& markdown) {
  std::vector<std::string> spans;
  std::istringstream in(markdown);
  bool fenced = false;
  for (std::string l; std::getline(in, l);) {
    if (l.rfind("```", 0) == 0) {
      fenced = !fenced;
      continue;
    }
    if (fenced) continue;
    for (std::size_t a = l.find('`'); a != std::string::npos; a = l.find('`', a)) {
      const std::size_t b = l.find('`', a + 1);
      if (b == std::string::npos) break;
      spans.push_back(l.substr(a + 1, b - a - 1));
      a = b + 1;
    }
  }
  return spans;
}

/// The text of the sources a page may name: the library, kernels, bindings, tests, benchmarks.
std::string sourceText() {
  static const std::set<std::string> kExt = {".hpp", ".cpp", ".h",     ".cl",
                                             ".c",   ".txt", ".cmake", ".py"};
  std::string all;
  for (const char* dir : {"sdk", "kernels", "bindings", "tests", "bench", "samples"})
    for (const auto& e : std::filesystem::recursive_directory_iterator(kRoot / dir))
      if (e.is_regular_file() && kExt.count(e.path().extension().string()))
        all += readText(e.path()) + "\n";
  return all;
}

bool isWordChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

/// `word` in `text`, not as part of a longer identifier.
bool hasWord(const std::string& text, const std::string& word) {
  for (std::size_t i = text.find(word); i != std::string::npos; i = text.find(word, i + 1)) {
    const bool before = i > 0 && isWordChar(text[i - 1]);
    const bool after = i + word.size() < text.size() && isWordChar(text[i + word.size()]);
    if (!before && !after) return true;
  }
  return false;
}

enum class SpanKind { Path, Name, Other };

SpanKind kindOf(const std::string& s) {
  if (s.empty() || (s.find(' ') != std::string::npos && s.rfind("TEST(", 0) != 0))
    return SpanKind::Other;
  if (s.find('/') != std::string::npos) return SpanKind::Path;
  const char c = s[0];
  if (!std::isalpha(static_cast<unsigned char>(c)) && c != '_') return SpanKind::Other;
  for (char x : s)
    if (!isWordChar(x) && std::string(":<>.(), ").find(x) == std::string::npos)
      return SpanKind::Other;
  return SpanKind::Name;
}

/// Whether a name on the page is in the sources: `TEST(A, B)` and `A.B` as a test, `x()` and
/// `a::b` as written or by their last part, `Describe<X>` as written.
bool nameExists(const std::string& text, std::string n) {
  if (n.size() > 2 && n.compare(n.size() - 2, 2, "()") == 0) n.resize(n.size() - 2);
  if (n.rfind("TEST(", 0) == 0) return text.find(n) != std::string::npos;
  const std::size_t dot = n.rfind('.');
  if (dot != std::string::npos) {
    if (std::isupper(static_cast<unsigned char>(n[0])))  // a GoogleTest suite.name
      return text.find("TEST(" + n.substr(0, dot) + ", " + n.substr(dot + 1) + ")") !=
             std::string::npos;
    // A CTest name: as written, or made by CMake from its prefix and a listed last part.
    return text.find(n) != std::string::npos ||
           (text.find(n.substr(0, dot + 1)) != std::string::npos &&
            hasWord(text, n.substr(dot + 1)));
  }
  if (hasWord(text, n)) return true;
  const std::size_t colons = n.rfind("::");
  return colons != std::string::npos && hasWord(text, n.substr(colons + 2));
}

TEST(DocSnippets, AddingAnActionNamesWhatExists) {
  const std::string page = readText(kRoot / "docs/adding-an-action.md");
  for (const Block& b : codeBlocks(page))
    EXPECT_TRUE(b.language != "cpp" && b.language != "c" && b.language != "json")
        << "line " << b.line << ": a code block here is checked by nothing; name files and "
        << "functions instead";
  const std::string text = sourceText();
  std::size_t paths = 0, names = 0;
  for (const std::string& s : codeSpans(page)) {
    switch (kindOf(s)) {
      case SpanKind::Path: {
        ++paths;
        const std::filesystem::path p = s.find('*') == std::string::npos
                                            ? kRoot / s
                                            : (kRoot / s).parent_path();  // kernels/*.h
        EXPECT_TRUE(std::filesystem::exists(p)) << "docs/adding-an-action.md names " << s;
        break;
      }
      case SpanKind::Name:
        ++names;
        EXPECT_TRUE(nameExists(text, s))
            << "docs/adding-an-action.md names " << s << ", which is in no source";
        break;
      case SpanKind::Other:
        break;
    }
  }
  // The page is a walk-through by name: if these fall, the spans are no longer read.
  EXPECT_GT(paths, 20u);
  EXPECT_GT(names, 40u);
}

TEST(DocSnippets, TheNameCheckerRefusesWhatIsNot) {
  const std::string text =
      "TEST(A, B) {}\nvoid fl_x(); namespace k { int y; }\n"
      "add_test(NAME e.gen.${what}) foreach(w schema)\n";
  EXPECT_TRUE(nameExists(text, "fl_x"));
  EXPECT_TRUE(nameExists(text, "fl_x()"));
  EXPECT_TRUE(nameExists(text, "k::y"));
  EXPECT_TRUE(nameExists(text, "A.B"));
  EXPECT_TRUE(nameExists(text, "TEST(A, B)"));
  EXPECT_TRUE(nameExists(text, "e.gen.schema"));
  EXPECT_FALSE(nameExists(text, "fl_"));
  EXPECT_FALSE(nameExists(text, "k::z"));
  EXPECT_FALSE(nameExists(text, "A.C"));
  EXPECT_FALSE(nameExists(text, "e.gen.dict"));
  EXPECT_EQ(kindOf("kernels/forces.h"), SpanKind::Path);
  EXPECT_EQ(kindOf("Describe<SpeedClamp>"), SpanKind::Name);
  EXPECT_EQ(kindOf("code spans"), SpanKind::Other);
  EXPECT_EQ(kindOf("f[0]"), SpanKind::Other);
  EXPECT_EQ(codeSpans("a `x` b `y/z`\n```sh\n`no`\n```\n"), (std::vector<std::string>{"x", "y/z"}));
}

}  // namespace
