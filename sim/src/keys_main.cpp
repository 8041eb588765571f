// feeddrive-keys: the scenario key tables, generated from the params structs' one lists
// (common/fields.hpp, sim/key_tables.hpp).
//
//   feeddrive-keys                      prints every table
//   feeddrive-keys --check FILE.md      exit 1 if FILE's marked tables differ from the lists
//   feeddrive-keys --write FILE.md      rewrites FILE's marked tables
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "feeddrive/sim/key_tables.hpp"

int main(int argc, char** argv) {
  CLI::App app{"feeddrive-keys: the scenario key tables of docs/scenario.md, from the params structs"};
  std::string check, write;
  app.add_option("--check", check, "a Markdown file whose marked tables must equal the generated ones (exit 1 otherwise)");
  app.add_option("--write", write, "a Markdown file whose marked tables are rewritten");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    if (check.empty() && write.empty()) {
      for (const auto& [name, text] : feeddrive::sim::key_tables()) std::printf("### %s\n\n%s\n", name.c_str(), text.c_str());
      return 0;
    }
    const std::string path = check.empty() ? write : check;
    std::ifstream in(path);
    if (!in) {
      std::fprintf(stderr, "error: %s: cannot be read\n", path.c_str());
      return 2;
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    const std::string generated = feeddrive::sim::with_key_tables(doc);
    if (!check.empty()) {
      if (generated == doc) return 0;
      std::fprintf(stderr, "error: %s: the key tables differ from the params structs' lists; run feeddrive-keys --write %s\n",
                   path.c_str(), path.c_str());
      return 1;
    }
    std::ofstream out(path);
    out << generated;
    if (!out) {
      std::fprintf(stderr, "error: %s: cannot be written\n", path.c_str());
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
