// Progress reporting: the callback that replaces the bar receives ordered
// events ending in one `finished` event, an exception it throws stops the
// operation, and an empty callback restores the default.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "core/progress.h"
#include "skybake/progress.h"

using namespace skybake;

namespace {

struct Restore {
    ~Restore() { set_progress_callback({}); }
};

} // namespace

TEST(Progress, CallbackReceivesTheEventsAndTheEnd) {
    Restore restore;
    std::vector<ProgressEvent> seen;
    std::vector<std::string> labels;
    set_progress_callback([&](const ProgressEvent& e) {
        seen.push_back(e);
        labels.emplace_back(e.label);
    });
    {
        Progress p("bake", 1000);
        p.set_status("half");
        for (int i = 0; i < 1000; ++i)
            p.advance(1);
        p.finish();
        p.finish(); // once only
    }
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(seen.back().finished);
    EXPECT_EQ(seen.back().done, 1000u);
    EXPECT_EQ(seen.back().total, 1000u);
    EXPECT_EQ(labels.back(), "bake");
    int finished = 0;
    for (std::size_t i = 0; i < seen.size(); ++i) {
        finished += seen[i].finished ? 1 : 0;
        if (i > 0)
            EXPECT_GE(seen[i].done, seen[i - 1].done);
    }
    EXPECT_EQ(finished, 1);
}

TEST(Progress, ACallbackCanStopTheOperation) {
    Restore restore;
    set_progress_callback([](const ProgressEvent& e) {
        if (e.finished)
            throw std::runtime_error("cancelled");
    });
    // The destructor swallows the exception; an explicit finish() passes it on.
    EXPECT_NO_THROW({ Progress p("train", 10); });
    Progress p("train", 10);
    EXPECT_THROW(p.finish(), std::runtime_error);
}

TEST(Progress, InstallingReturnsThePreviousCallback) {
    Restore restore;
    int calls = 0;
    EXPECT_FALSE(set_progress_callback([&](const ProgressEvent&) { ++calls; }));
    const ProgressCallback previous = set_progress_callback({});
    ASSERT_TRUE(previous);
    {
        Progress p("render", 1); // default again: nothing reaches the old callback
        p.advance(1);
    }
    EXPECT_EQ(calls, 0);
}
