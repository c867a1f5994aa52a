/* SPDX-License-Identifier: MIT */
/* The shared per-point layers of a PointNet stage, written once for both precisions: LIDET_PN_BLOCK points at a
 * time are loaded into the model frame, run through the layers in two ping-pong buffers, and the last layer's
 * block output is folded into a running maximum over the points (no N x C buffer). lidet_pointnet.c (float)
 * and lidet_pointnet_q.c (int8) include this file once each, after defining:
 *   PNB_FN                      name of the function defined here
 *   PNB_LAYER_T, PNB_BUFS_T     the layer descriptor and the scratch view (with act[2])
 *   PNB_PTS_T, PNB_FRAME_T      the proposal's point type and the frame (rotation, shift) argument
 *   PNB_MAX_INIT(b, n)          reset the running maximum of n channels
 *   PNB_LOAD(b, pts, nb, f)     load nb points into the model frame; yields the block (const void *)
 *   PNB_DENSE(ly, in, nb, b, l) layer l on the block `in` (the loaded points when l == 0)
 *   PNB_STORE(ly, nb, b, dst)   write layer l's output (hidden layers) to dst, the next layer's input
 *   PNB_FOLD_MAX(ly, nb, b, l)  fold the last layer's output into the running maximum
 *   PNB_FUSED(ly, in, nb, b, l, dst)  optional: the whole layer in one pass (DENSE and STORE to dst, or DENSE and
 *                               FOLD_MAX when dst is NULL); nonzero when it did, 0 to take DENSE and STORE/FOLD_MAX
 * The float kernel writes its output in PNB_DENSE (STORE does nothing); the int8 one accumulates in int32
 * (DENSE), requantizes hidden layers (STORE) and takes the maximum on the accumulators (FOLD_MAX).
 * Not a public header; include nowhere else. */

static void PNB_FN(const PNB_LAYER_T *layers, uint32_t n_layers, const PNB_BUFS_T *b, const PNB_PTS_T *pts,
                   uint32_t n, const PNB_FRAME_T *f)
{
    uint32_t p0, l;
    PNB_MAX_INIT(b, layers[n_layers - 1u].n_out);
    for (p0 = 0; p0 < n; p0 += LIDET_PN_BLOCK)
    {
        const uint32_t nb = n - p0 < LIDET_PN_BLOCK ? n - p0 : LIDET_PN_BLOCK;
        const void *cur = PNB_LOAD(b, pts + 3u * p0, nb, f);
        for (l = 0; l < n_layers; ++l)
        {
            const PNB_LAYER_T *ly = &layers[l];
            const int last = l + 1u == n_layers;
            if (!PNB_FUSED(ly, cur, nb, b, l, last ? 0 : b->act[l & 1u]))
            {
                PNB_DENSE(ly, cur, nb, b, l);
                if (last)
                {
                    PNB_FOLD_MAX(ly, nb, b, l);
                }
                else
                {
                    PNB_STORE(ly, nb, b, b->act[l & 1u]);
                }
            }
            if (!last)
            {
                cur = b->act[l & 1u];
            }
        }
    }
}
