// SPDX-License-Identifier: MIT
// A shared library that is not Embree: tests/cli/embree_loading_test.py puts it where the
// dynamic loader looks for libembree3.so.3 first.
extern "C" int whitted_not_embree() {
    return 0;
}
