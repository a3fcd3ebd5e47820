#pragma once
// Bad input must end in one InputError line: f() throws it, its message holds `fragment` and no newline.
#include "core/errors.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace kushner::test {

inline void expect_input_error(const std::function<void()>& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no InputError (expected '" << fragment << "')";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace kushner::test
