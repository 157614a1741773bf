// expect_error<E>(fn, words): fn throws E and its message holds every word,
// so tests check that an error names what is wrong, not only that it throws.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

namespace hj::testing_support {

template <typename E>
void expect_error(const std::function<void()>& fn, const std::vector<std::string>& words) {
  try {
    fn();
    ADD_FAILURE() << "no exception; expected one naming \"" << words.front() << "\"";
  } catch (const E& e) {
    const std::string what = e.what();
    for (const auto& w : words) EXPECT_NE(what.find(w), std::string::npos) << "\"" << w << "\" not in: " << what;
  }
}

}  // namespace hj::testing_support
