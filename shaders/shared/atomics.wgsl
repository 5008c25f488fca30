// A float atomic add on one array, included once per array as a template:
//   #include "shared/atomics.wgsl" ARR=node_acc FN=node_add
// {{ARR}} is an array<atomic<f32>> when the adapter has SHADER_FLOAT32_ATOMIC
// (FLOAT_ATOMICS), else an array<atomic<u32>> of f32 bits updated by a
// compare-exchange loop. (WGSL cannot pass storage pointers to functions,
// hence one function per array.)

fn {{FN}}(i: u32, v: f32) {
#if FLOAT_ATOMICS
    atomicAdd(&{{ARR}}[i], v);
#else
    var old = atomicLoad(&{{ARR}}[i]);
    loop {
        let r = atomicCompareExchangeWeak(&{{ARR}}[i], old, bitcast<u32>(bitcast<f32>(old) + v));
        if r.exchanged {
            break;
        }
        old = r.old_value;
    }
#endif
}
