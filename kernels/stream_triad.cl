// STREAM triad, a[i] = b[i] + s * c[i]: the memory-bandwidth anchor every roofline ratio in bench/
// is taken against, measured on the same device in the same run.
__kernel void stream_triad(__global float* restrict a, __global const float* restrict b,
                           __global const float* restrict c, const float s, const uint n) {
  const uint i = get_global_id(0);
  if (i < n) a[i] = b[i] + s * c[i];
}
