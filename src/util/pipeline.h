// Blocks of work read in order, processed in parallel, and written in order: the shape of every
// streaming program here (matrix rows through a product, sky patches through gendaymtx). At most
// twice as many blocks as threads are in flight, so memory stays bounded.
#pragma once

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <deque>
#include <memory>
#include <mutex>

#include "util/errors.h"

namespace dayflux {

// produce() returns the next block or nullptr at the end (called in order, one at a time);
// work(block) runs in parallel; consume(block) is called in production order. An exception from
// any stage ends the pipeline and is rethrown here, the blocks in flight freed (TBB drops the
// tokens of a cancelled pipeline without passing them on).
template <class Block, class Produce, class Work, class Consume>
void OrderedPipeline(Produce produce, Work work, Consume consume) {
    const size_t tokens = 2 * static_cast<size_t>(tbb::this_task_arena::max_concurrency());
    // The blocks in flight, owned here in production order (consume takes them in that order),
    // so that those a failed pipeline leaves behind are freed with it.
    std::mutex flying_mutex;
    std::deque<std::unique_ptr<Block>> flying;
    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, Block *>(tbb::filter_mode::serial_in_order,
                                        [&](tbb::flow_control &fc) -> Block * {
                                            std::unique_ptr<Block> b = produce();
                                            if (!b) fc.stop();
                                            Block *raw = b.get();
                                            const std::lock_guard lock(flying_mutex);
                                            if (raw) flying.push_back(std::move(b));
                                            return raw;
                                        }) &
            tbb::make_filter<Block *, Block *>(tbb::filter_mode::parallel,
                                               [&](Block *b) {
                                                   work(*b);
                                                   return b;
                                               }) &
            tbb::make_filter<Block *, void>(tbb::filter_mode::serial_in_order, [&](Block *b) {
                consume(*b);
                const std::lock_guard lock(flying_mutex);
                CHECK(flying.front().get() == b);
                flying.pop_front();
            }));
}

}  // namespace dayflux
