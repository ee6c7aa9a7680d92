use placewords::experiment::*;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let laps: Option<usize> = std::env::args().nth(2).map(|s| s.parse().unwrap());
    let scn = placewords::spec::scenario::load_scenario(std::path::Path::new(&p)).unwrap();
    let opts = ExperimentOptions { levels: vec![1, 2], icp: false, laps, quiet: true };
    let exp = run_scenario(&scn, &opts).unwrap();
    for (l, rec) in &exp.recognitions {
        let pairs = placewords::eval::metrics::scored_pairs(rec, 1.0);
        let mut h = [0usize; 8];
        for p in &pairs { let d = p.query_truth.0.distance(&p.past_truth.0); let b = if d < 1.0 {0} else if d < 2.0 {1} else if d < 3.0 {2} else if d < 5.0 {3} else if d < 10.0 {4} else if d < 20.0 {5} else if d < 40.0 {6} else {7}; h[b] += 1; }
        println!("levels {l}: pairs {} hist <1,<2,<3,<5,<10,<20,<40,>40: {:?}", pairs.len(), h);
        // per match: mean error, word sizes
        let mut bad = 0; let mut total = 0;
        for m in &rec.matches { let errs: Vec<f64> = m.pairs.iter().filter_map(|p| { let q = pairs.iter().find(|s| s.query == p.query && s.past == p.past)?; Some(q.query_truth.0.distance(&q.past_truth.0)) }).collect(); if errs.is_empty() {continue;} total += 1; let mean = errs.iter().sum::<f64>() / errs.len() as f64; if mean > 3.0 { bad += 1; if bad <= 8 { println!("  bad match lv{} n{} pairs {} mean err {:.1} words {:?}", m.levels, m.ngram_len, m.pairs.len(), mean, m.word_pairs.iter().map(|(a,b)| (a.level, b.level)).collect::<Vec<_>>()); } } }
        println!("  matches with mean err > 3 m: {bad}/{total}");
    }
}
