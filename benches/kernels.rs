//! Ray-primitive tests per second of every shape's scalar and packet kernels on
//! the same rays (`Throughput::Elements` = rays tested).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use raypack::bench::kernels::{KernelSetup, SetupVisitor, for_each_setup, run_packet, run_scalar};
use raypack::geometry::Intersect;
use wide::{f32x8, f32x16};

struct Register<'a>(&'a mut Criterion);

impl SetupVisitor for Register<'_> {
    fn visit<K: Intersect>(&mut self, setup: &KernelSetup<K>) {
        let mut group = self.0.benchmark_group(format!("kernel/{}", setup.name));
        group.throughput(Throughput::Elements(setup.rays.len() as u64));
        let p8 = setup.packets::<f32x8>();
        let p16 = setup.packets::<f32x16>();
        group.bench_function("scalar", |b| b.iter(|| run_scalar(&setup.kernel, &setup.rays)));
        group.bench_function("packet8", |b| b.iter(|| run_packet(&setup.kernel, &p8)));
        group.bench_function("packet16", |b| b.iter(|| run_packet(&setup.kernel, &p16)));
        group.finish();
    }
}

fn kernels(c: &mut Criterion) {
    for_each_setup(4096, 1, &mut Register(c));
}

criterion_group!(benches, kernels);
criterion_main!(benches);
