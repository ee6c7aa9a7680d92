use placewords::experiment::*;
use placewords::recognizer::*;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let scn = placewords::spec::scenario::load_scenario(std::path::Path::new(&p)).unwrap();
    let opts = ExperimentOptions { levels: vec![1], icp: false, laps: Some(2), quiet: true };
    let (runs, _) = simulate(&scn, &opts).unwrap();
    let mut rec = Recognizer::new(RecognizerConfig::default()).unwrap();
    for f in runs[0].frames() { rec.push(f.odom, &f.scan); }
    rec.finish();
    let w = rec.level_words(0);
    println!("level-0 words in 2 laps: {}", w.len());
    for x in w.iter().take(60) { print!("({} {} {:.0}) ", x.class, x.size, x.angle_deg); }
    println!();
}
