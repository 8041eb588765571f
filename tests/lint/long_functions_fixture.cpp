// Fixture of tests/lint/long_functions_test.py: functions whose signatures hold braces (a default
// argument `= {}`, `= T{...}`, a lambda), an operator, and the functions after them, which the
// scan of scripts/long-functions.py must still see. Not built; each function's length
// (signature to closing brace) is in the comment above it.
#include <functional>
#include <string>
#include <vector>

namespace fixture {

struct Options {
  int level = 0;
};

// 15 lines.
int brace_default(int x, std::vector<int> v = {}) {
  x += 0;
  x += 1;
  x += 2;
  x += 3;
  x += 4;
  x += 5;
  x += 6;
  x += 7;
  x += 8;
  x += 9;
  x += 10;
  x += 11;
  return x + static_cast<int>(v.size());
}

// 15 lines, after the one above: it was missed too.
int after_brace_default(int x) {
  x += 0;
  x += 1;
  x += 2;
  x += 3;
  x += 4;
  x += 5;
  x += 6;
  x += 7;
  x += 8;
  x += 9;
  x += 10;
  x += 11;
  return x;
}

// 15 lines.
int init_default(int x, Options o = Options{1}) {
  x += 0;
  x += 1;
  x += 2;
  x += 3;
  x += 4;
  x += 5;
  x += 6;
  x += 7;
  x += 8;
  x += 9;
  x += 10;
  x += 11;
  return x + o.level;
}

// 16 lines (clang-format puts its signature on two).
int lambda_default(
    int x, const std::function<int(int)>& f = [](int y) { return y; }) {
  x += 0;
  x += 1;
  x += 2;
  x += 3;
  x += 4;
  x += 5;
  x += 6;
  x += 7;
  x += 8;
  x += 9;
  x += 10;
  x += 11;
  return f(x);
}

struct Value {
  int x = 0;
  // 15 lines.
  bool operator==(const Value& o) const {
    if (x == 0) return o.x == 0;
    if (x == 1) return o.x == 1;
    if (x == 2) return o.x == 2;
    if (x == 3) return o.x == 3;
    if (x == 4) return o.x == 4;
    if (x == 5) return o.x == 5;
    if (x == 6) return o.x == 6;
    if (x == 7) return o.x == 7;
    if (x == 8) return o.x == 8;
    if (x == 9) return o.x == 9;
    if (x == 10) return o.x == 10;
    if (x == 11) return o.x == 11;
    return x == o.x;
  }
};

// long-function: a fixture of a stated reason (listed only with --all).
int with_reason(int x) {
  x += 0;
  x += 1;
  x += 2;
  x += 3;
  x += 4;
  x += 5;
  x += 6;
  x += 7;
  x += 8;
  x += 9;
  x += 10;
  x += 11;
  return x;
}

// 1 line: under the limit.
int short_one(int x = {}) { return x; }

// A declaration with a brace default argument: no body, not a function.
int declared(int x, std::vector<int> v = {});

// 15 lines, the last of the file.
int last_one(int x) {
  x += 0;
  x += 1;
  x += 2;
  x += 3;
  x += 4;
  x += 5;
  x += 6;
  x += 7;
  x += 8;
  x += 9;
  x += 10;
  x += 11;
  return x;
}

}  // namespace fixture
