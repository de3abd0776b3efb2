// Blocks of work read in order, processed in parallel, and written in order: the shape of every
// streaming program here (matrix rows through a product, sky patches through gendaymtx). At most
// twice as many blocks as threads are in flight, so memory stays bounded.
#pragma once

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <memory>

namespace dayflux {

// produce() returns the next block or nullptr at the end (called in order, one at a time);
// work(block) runs in parallel; consume(block) is called in production order.
template <class Block, class Produce, class Work, class Consume>
void OrderedPipeline(Produce produce, Work work, Consume consume) {
    const size_t tokens = 2 * static_cast<size_t>(tbb::this_task_arena::max_concurrency());
    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, Block *>(tbb::filter_mode::serial_in_order,
                                        [&](tbb::flow_control &fc) -> Block * {
                                            std::unique_ptr<Block> b = produce();
                                            if (!b) fc.stop();
                                            return b.release();
                                        }) &
            tbb::make_filter<Block *, Block *>(tbb::filter_mode::parallel,
                                               [&](Block *b) {
                                                   work(*b);
                                                   return b;
                                               }) &
            tbb::make_filter<Block *, void>(tbb::filter_mode::serial_in_order, [&](Block *b) {
                std::unique_ptr<Block> owned(b);
                consume(*owned);
            }));
}

}  // namespace dayflux
