// The plugin's entry points; the selector itself is in retrieval_pair_selector.cc.

#include "retrieval_pair_selector.h"

TESSERA_PLUGIN_OPTIONS(tessera::retrieval::RetrievalOptions,
                       tessera::retrieval::VisitRetrievalOptions)
TESSERA_PLUGIN(pair_selector, tessera::retrieval::RetrievalPairSelector, "retrieval", "1.0.0",
               "Each image with its k nearest images by VLAD global descriptors over a k-means "
               "codebook (faiss), trained on the run or read from `tessera vocab`'s file")
