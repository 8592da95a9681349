// constants.wgsl: numbers more than one module needs.

const PI: f32 = 3.14159265358979;
// The far end of a ray that has none (trace_closest's tmax).
const INFINITY: f32 = 3.4e38;
