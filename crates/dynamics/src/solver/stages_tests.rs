//! Tests of the stage machinery against a sequential oracle: every block of every stage
//! runs exactly once, after every block of the previous stage, and data passed from stage
//! to stage comes out bit for bit as in a plain sequential loop, on 1, 2, 3 and 8 threads.

use super::*;
use std::sync::atomic::AtomicUsize;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

#[test]
fn block_ranges_cover_the_items_in_order() {
    for len in [0usize, 1, 2, 5, 16, 17, 1000] {
        for blocks in 1..=9 {
            let mut next = 0;
            for b in 0..blocks {
                let r = block_range(len, blocks, b);
                assert_eq!(r.start, next, "len {len} blocks {blocks} block {b}");
                assert!(r.end >= r.start);
                next = r.end;
            }
            assert_eq!(next, len);
        }
        assert_eq!(block_count(len, 16), len.div_ceil(16));
    }
    assert_eq!(block_count(5, 0), 5, "a zero block size counts as one");
}

#[test]
fn every_block_runs_once_after_the_previous_stage() {
    // Stage s has s % 7 blocks (empty stages are left out); each block checks that every
    // block of the previous kept stage finished before it started.
    let sizes: Vec<usize> = (0..60).map(|s| s % 7).collect();
    for threads in [1, 2, 3, 8] {
        let mut list = StageList::<usize>::default();
        for (s, &n) in sizes.iter().enumerate() {
            list.push(s, n);
        }
        assert_eq!(
            list.stages().len(),
            sizes.iter().filter(|&&n| n > 0).count()
        );
        let kept: Vec<usize> = list.stages().iter().map(|s| s.kind).collect();
        let runs: Vec<AtomicUsize> = (0..sizes.len() * 7).map(|_| AtomicUsize::new(0)).collect();
        let finished: Vec<AtomicUsize> = (0..sizes.len()).map(|_| AtomicUsize::new(0)).collect();
        pool(threads).install(|| {
            list.run(threads, |s, b, blocks| {
                assert_eq!(blocks, sizes[s]);
                let k = kept.iter().position(|&x| x == s).expect("a kept stage");
                if k > 0 {
                    let p = kept[k - 1];
                    assert_eq!(finished[p].load(Ordering::SeqCst), sizes[p], "stage {s}");
                }
                runs[s * 7 + b].fetch_add(1, Ordering::SeqCst);
                finished[s].fetch_add(1, Ordering::SeqCst);
            })
        });
        for (s, &n) in sizes.iter().enumerate() {
            for b in 0..7 {
                let expect = usize::from(b < n);
                assert_eq!(
                    runs[s * 7 + b].load(Ordering::SeqCst),
                    expect,
                    "{threads} threads"
                );
            }
        }
        assert_eq!(list.durations().count(), list.stages().len());
    }
}

/// A relaxation over 10 000 values in 40 stages: each stage reads its neighbours' values of
/// the previous stage (written by other blocks, maybe on other threads) and writes its own.
fn relax(threads: usize, stages: usize) -> Vec<f64> {
    let n = 10_000;
    let a: Vec<AtomicU64> = (0..n)
        .map(|i| AtomicU64::new((i as f64).sin().to_bits()))
        .collect();
    let b: Vec<AtomicU64> = (0..n).map(|_| AtomicU64::new(0)).collect();
    let mut list = StageList::<usize>::default();
    for s in 0..stages {
        list.push(s, block_count(n, 97));
    }
    let step = |s: usize, blk: usize, blocks: usize| {
        let (src, dst) = if s.is_multiple_of(2) {
            (&a, &b)
        } else {
            (&b, &a)
        };
        let get = |i: usize| f64::from_bits(src[i].load(Ordering::Relaxed));
        for i in block_range(n, blocks, blk) {
            let (l, r) = (get(i.saturating_sub(1)), get((i + 1).min(n - 1)));
            let v = 0.25 * l + 0.5 * get(i) + 0.25 * r + 1e-3 * s as f64;
            dst[i].store(v.to_bits(), Ordering::Relaxed);
        }
    };
    pool(threads).install(|| list.run(threads, step));
    let out = if stages.is_multiple_of(2) { &a } else { &b };
    out.iter()
        .map(|x| f64::from_bits(x.load(Ordering::Relaxed)))
        .collect()
}

#[test]
fn results_are_bit_identical_to_the_sequential_loop_on_any_thread_count() {
    let one = relax(1, 41);
    for threads in [2, 3, 8] {
        let many = relax(threads, 41);
        let same = one
            .iter()
            .zip(&many)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "{threads} threads differ from one");
    }
    // The oracle is not trivial: the values moved.
    assert!(one.iter().any(|&v| v != 0.0));
}

#[test]
fn an_empty_list_and_a_reused_list_run() {
    let mut list = StageList::<u8>::default();
    list.run(4, |_, _, _| panic!("no stage"));
    let count = AtomicUsize::new(0);
    for _ in 0..3 {
        list.clear();
        list.push(1, 3);
        list.push(2, 0);
        list.push(3, 2);
        pool(2).install(|| {
            list.run(2, |_, _, _| {
                count.fetch_add(1, Ordering::SeqCst);
            })
        });
    }
    assert_eq!(count.load(Ordering::SeqCst), 15);
}

#[test]
fn a_panicking_block_reaches_the_caller_without_hanging() {
    let mut list = StageList::<usize>::default();
    for s in 0..20 {
        list.push(s, 8);
    }
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        pool(2).install(|| {
            list.run(2, |s, b, _| {
                if s == 5 && b == 3 {
                    panic!("block 3 of stage 5");
                }
            })
        })
    }));
    assert!(r.is_err());
}

#[test]
fn worker_starts_are_spread_over_the_blocks() {
    for blocks in [1u32, 2, 3, 7, 16, 1000] {
        for workers in [1usize, 2, 3, 8] {
            let starts: Vec<u32> = (0..workers)
                .map(|w| worker_start(w, workers, blocks))
                .collect();
            assert_eq!(starts[0], 0);
            assert!(starts.windows(2).all(|p| p[0] <= p[1]));
            assert!(starts.iter().all(|&s| s < blocks));
            if blocks as usize >= workers {
                // Distinct starts: each worker begins in its own share.
                assert!(starts.windows(2).all(|p| p[0] < p[1]));
            }
        }
    }
    // A worker index past the count (never passed) still gives a valid block.
    assert!(worker_start(9, 2, 5) < 5);
}

/// The forward and backward sweeps from the workers' start blocks claim every block of
/// every stage exactly once, for stages with many more blocks than threads, with threads
/// that may join late or be slowed down at random.
#[test]
fn start_block_sweeps_claim_every_block_once() {
    let sizes: Vec<usize> = (0..40).map(|s| 1 + (s * 7) % 37).collect();
    for threads in [2, 3, 5, 8] {
        let mut list = StageList::<usize>::default();
        for (s, &n) in sizes.iter().enumerate() {
            list.push(s, n);
        }
        let runs: Vec<AtomicUsize> = (0..sizes.len() * 37).map(|_| AtomicUsize::new(0)).collect();
        for round in 0..4 {
            pool(threads).install(|| {
                list.run(threads, |s, b, _| {
                    // Uneven block costs, so that workers overtake and steal.
                    let spin = (s * 31 + b * 17 + round) % 13;
                    for _ in 0..spin * 200 {
                        std::hint::spin_loop();
                    }
                    runs[s * 37 + b].fetch_add(1, Ordering::SeqCst);
                })
            });
        }
        for (s, &n) in sizes.iter().enumerate() {
            for b in 0..37 {
                let expect = if b < n { 4 } else { 0 };
                assert_eq!(
                    runs[s * 37 + b].load(Ordering::SeqCst),
                    expect,
                    "{threads} threads, stage {s}, block {b}"
                );
            }
        }
    }
}
