// feeddrive-keys: the scenario key tables, generated from the params structs' one lists
// (common/fields.hpp, sim/key_tables.hpp).
//
//   feeddrive-keys                      prints every table
//   feeddrive-keys --check FILE.md      exit 1 if FILE's marked tables differ from the lists,
//                                       2 if a list's table is not marked in FILE
//   feeddrive-keys --write FILE.md      rewrites FILE's marked tables (docs/cli.md)
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/sim/key_tables.hpp"
#include "feeddrive/tool/main.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-keys: the scenario key tables of docs/scenario.md, from the params structs"};
  std::string check, write;
  app.add_option("--check", check,
                 "a Markdown file whose marked tables must equal the generated ones (exit 1 otherwise; 2 if "
                 "a table is not marked)");
  app.add_option("--write", write, "a Markdown file whose marked tables are rewritten");
  tool::Options opt;
  opt.name = "feeddrive-keys";
  return tool::run(app, argc, argv, opt, [&] {
    if (check.empty() && write.empty()) {
      for (const auto& [name, text] : sim::key_tables()) std::printf("### %s\n\n%s\n", name.c_str(), text.c_str());
      return kExitOk;
    }
    const std::string path = check.empty() ? write : check;
    std::ifstream in(path);
    if (!in) throw BadInput(path + ": cannot be read");
    std::ostringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    const std::string generated = tool::input_step([&] { return sim::with_key_tables(doc); });
    if (!check.empty()) {
      if (generated == doc) return kExitOk;
      throw std::runtime_error(
          path + ": the key tables differ from the params structs' lists; run feeddrive-keys --write " + path);
    }
    std::ofstream out(path);
    out << generated;
    if (!out) throw std::runtime_error(path + ": cannot be written");
    return kExitOk;
  });
}
