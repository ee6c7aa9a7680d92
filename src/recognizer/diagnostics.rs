//! What the word matcher saw of a run ([`MatchDiagnostics`]), and how it says so: the
//! recognizer's side of [`crate::place::Diagnostics`]. A run without pairs is explained from
//! these counters (the longest chain of matching words against τ, the verification checks that
//! turned candidates down, the travel τ words need against the revisits' length). The matcher's
//! side of it is here too: the counters it hands over, and the rejected candidates it samples.

use super::matcher::WordMatcher;
use super::types::Direction;
use super::words::WordId;
use crate::place::{CandidateCounts, Diagnostics, ObsId, RejectedCandidate};

/// Rejected candidates sampled at most (the first ones; 32 bytes each).
pub(crate) const MAX_REJECTED_SAMPLES: usize = 10_000;

/// Why verification turned a candidate n-gram down.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rejection {
    /// Odometric travel between its words differs between the two sides.
    Travel,
    /// Odometric heading change between its words differs between the two sides.
    Turn,
    /// The aligned raw densities differ too much.
    Density,
    /// The free space lies on different sides of the path at the two visits.
    Sides,
    /// Read backwards, its current side turns by less than `reverse_min_turn_deg`.
    Straight,
}

impl Rejection {
    /// Every check, in the order verification applies them.
    pub const ALL: [Rejection; 5] = [
        Rejection::Travel,
        Rejection::Turn,
        Rejection::Density,
        Rejection::Sides,
        Rejection::Straight,
    ];

    /// Its name in reports ("travel", "turn", …).
    pub fn name(self) -> &'static str {
        match self {
            Rejection::Travel => "travel",
            Rejection::Turn => "turn",
            Rejection::Density => "density",
            Rejection::Sides => "sides",
            Rejection::Straight => "straight",
        }
    }

    /// Its index in [`Rejection::ALL`] ([`RejectedCandidate::check`]).
    pub fn index(self) -> usize {
        self as usize
    }
}

/// Counts of candidate n-grams (τ reached, candidate gap satisfied) by outcome, summed over
/// level configurations and directions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct VerificationCounts {
    pub accepted: usize,
    pub rejected_travel: usize,
    pub rejected_turn: usize,
    pub rejected_density: usize,
    /// Free space on different sides of the path (`verify_max_lateral_rms`).
    #[serde(default)]
    pub rejected_sides: usize,
    /// Read backwards along a path that does not turn (`reverse_min_turn_deg`).
    #[serde(default)]
    pub rejected_straight: usize,
}

impl VerificationCounts {
    /// Candidates verification turned down, for any reason.
    pub fn rejected(&self) -> usize {
        Rejection::ALL.iter().map(|&r| self.of(r)).sum()
    }

    /// Candidates turned down by check `r`.
    pub fn of(&self, r: Rejection) -> usize {
        match r {
            Rejection::Travel => self.rejected_travel,
            Rejection::Turn => self.rejected_turn,
            Rejection::Density => self.rejected_density,
            Rejection::Sides => self.rejected_sides,
            Rejection::Straight => self.rejected_straight,
        }
    }

    pub(crate) fn add(&mut self, r: Rejection) {
        match r {
            Rejection::Travel => self.rejected_travel += 1,
            Rejection::Turn => self.rejected_turn += 1,
            Rejection::Density => self.rejected_density += 1,
            Rejection::Sides => self.rejected_sides += 1,
            Rejection::Straight => self.rejected_straight += 1,
        }
    }
}

/// What the matcher saw, so that a run without matches can say why.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MatchDiagnostics {
    /// Per level configuration (index k: k + 1 levels), the longest chain of matching word pairs
    /// found, in word pairs.
    pub longest_chain: Vec<usize>,
    /// Per level configuration, its minimum n-gram size τ.
    pub min_ngram: Vec<usize>,
    /// Chains that reached τ but began within the candidate gap of their past side.
    pub within_gap: usize,
    /// Candidate n-grams by verification outcome.
    pub verification: VerificationCounts,
    /// Steps between scans longer than `max_interpolation_m`, each observed once where one
    /// observation per spacing was due (filled by [`crate::recognizer::Recognizer`]; written
    /// only when not 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub long_steps: usize,
    /// Words a chain read backwards needs beyond τ (`reverse_extra_ngram`; 0 without reverse
    /// matching).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub reverse_extra_ngram: usize,
    /// The first 10,000 candidates verification turned down, one observation pair each (not
    /// written: the harness scores them against the truth).
    #[serde(skip)]
    pub rejected: Vec<RejectedCandidate>,
    /// Mean travel a level-0 word spans, metres (0 before the first word closes): a chain of
    /// τ words needs a revisit about τ times this long.
    #[serde(default)]
    pub mean_word_m: f64,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The sentence saying how far a chain of `tau` words (`backwards` when read backwards) reaches.
fn need_sentence(tau: usize, backwards: usize, same_need_m: f64, opposite_need_m: f64) -> String {
    if backwards == tau {
        format!("τ = {tau} words need about {same_need_m:.0} m")
    } else {
        format!(
            "τ = {tau} words need about {same_need_m:.0} m ({backwards} read backwards, about \
             {opposite_need_m:.0} m)"
        )
    }
}

impl Diagnostics for MatchDiagnostics {
    /// The matcher's side of a run without pairs, with a word on steps too long to observe
    /// along their length when there were any.
    fn no_match_reason(&self) -> String {
        let why = self.matcher_reason();
        match self.long_steps {
            0 => why,
            n => format!(
                "{why}; {} (words break there: raise it)",
                long_steps_sentence(n)
            ),
        }
    }

    fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }

    fn candidates(&self) -> CandidateCounts {
        CandidateCounts {
            accepted: self.verification.accepted,
            rejected: self.verification.rejected(),
        }
    }

    fn checks(&self) -> Vec<String> {
        Rejection::ALL
            .iter()
            .map(|r| r.name().to_string())
            .collect()
    }

    fn rejected(&self) -> &[RejectedCandidate] {
        &self.rejected
    }

    /// Whether the revisits are long enough for a chain of τ words (the smallest τ; more read
    /// backwards) at the run's mean word length: when they are not, no tolerance on the words
    /// can help; when they are, the words differ between visits.
    fn revisit_length_reason(&self, same_m: f64, opposite_m: f64) -> Option<String> {
        let (tau, backwards) = (
            self.chain_words(Direction::Same)?,
            self.chain_words(Direction::Opposite)?,
        );
        let (same_need_m, opposite_need_m) = (
            tau as f64 * self.mean_word_m,
            backwards as f64 * self.mean_word_m,
        );
        let stretch = format!(
            "the longest stretch along which every observation has a revisit is {same_m:.1} m \
             driven the same way and {opposite_m:.1} m the other way, and a word spans {:.1} m on \
             average",
            self.mean_word_m
        );
        let need = need_sentence(tau, backwards, same_need_m, opposite_need_m);
        Some(if same_m < same_need_m && opposite_m < opposite_need_m {
            format!("{stretch}: {need}, so the revisits are too short for a chain")
        } else {
            format!(
                "{stretch}: {need}, so the revisits are long enough and the words differ between visits"
            )
        })
    }

    fn direction_length_reason(&self, direction: Direction, longest_m: f64) -> Option<String> {
        let words = self.chain_words(direction)?;
        let (way, chain) = match direction {
            Direction::Same => ("driven the same way", "a chain"),
            Direction::Opposite => ("the other way", "a chain read backwards"),
        };
        let need_m = words as f64 * self.mean_word_m;
        let verdict = if longest_m < need_m {
            "too short for one"
        } else {
            "long enough for one"
        };
        Some(format!(
            "the longest stretch along which every observation has a revisit {way} is \
             {longest_m:.1} m, and {chain} needs {words} words, about {need_m:.0} m at {:.1} m a \
             word: {verdict}",
            self.mean_word_m
        ))
    }

    fn notes(&self) -> Vec<String> {
        match self.long_steps {
            0 => Vec::new(),
            n => vec![format!(
                "{} (raise it to observe them along their length)",
                long_steps_sentence(n)
            )],
        }
    }
}

impl MatchDiagnostics {
    /// The words a chain needs read in `direction` (the smallest τ, plus `reverse_extra_ngram`
    /// read backwards); `None` when the run says nothing of word lengths.
    fn chain_words(&self, direction: Direction) -> Option<usize> {
        let tau = *self.min_ngram.first()?;
        if self.mean_word_m <= 0.0 || tau == 0 {
            return None;
        }
        Some(match direction {
            Direction::Same => tau,
            Direction::Opposite => tau + self.reverse_extra_ngram,
        })
    }

    /// What the matcher saw of a run without pairs.
    fn matcher_reason(&self) -> String {
        let v = &self.verification;
        if v.accepted > 0 {
            return format!(
                "{} matches were accepted but none kept an aligned pair beyond the candidate gap",
                v.accepted
            );
        }
        if v.rejected() > 0 {
            return format!(
                "every candidate was rejected by verification: {} (travel {}, turn {}, density {}, sides {}, straight {})",
                v.rejected(),
                v.rejected_travel,
                v.rejected_turn,
                v.rejected_density,
                v.rejected_sides,
                v.rejected_straight
            );
        }
        let chains: Vec<String> = self
            .longest_chain
            .iter()
            .zip(&self.min_ngram)
            .enumerate()
            .map(|(k, (l, t))| format!("{l} (τ = {t}) at {} level{}", k + 1, plural(k + 1)))
            .collect();
        let chains = chains.join(", ");
        let short = self
            .longest_chain
            .iter()
            .zip(&self.min_ngram)
            .all(|(l, t)| l < t);
        if short || self.within_gap == 0 {
            format!("no word sequence long enough: the longest chain of matching words is {chains}")
        } else {
            format!(
                "the {} chains that reached τ all began within the candidate gap of their past \
                 side (a repeat inside one pass); the longest chain of matching words is {chains}",
                self.within_gap
            )
        }
    }
}

/// `n` steps between scans too long to observe along their length, in words (the reason of a
/// run without pairs, and the table's note when there are pairs).
pub fn long_steps_sentence(n: usize) -> String {
    format!(
        "{n} step{} between scans {} longer than max_interpolation_m and observed once where \
         more observations were due",
        plural(n),
        if n == 1 { "was" } else { "were" }
    )
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// What the matcher hands over of what it saw.
impl WordMatcher {
    /// What the matcher saw so far, to say why nothing matched.
    pub fn diagnostics(&self) -> MatchDiagnostics {
        let levels = self.levels;
        MatchDiagnostics {
            longest_chain: self.longest[..levels].iter().map(|&l| l as usize).collect(),
            min_ngram: self.tau[..levels].to_vec(),
            within_gap: self.within_gap,
            verification: self.rejections,
            rejected: self.rejected.clone(),
            long_steps: 0,
            reverse_extra_ngram: self.matcher_opts.opposite_extra_ngram(),
            mean_word_m: if self.level0_words == 0 {
                0.0
            } else {
                self.level0_travel_m / self.level0_words as f64
            },
        }
    }

    /// A rejected candidate's sample: at its newest and at its oldest word pair, the middle
    /// observation of the current word and the past observation the n-gram's shift aligns with
    /// it (clamped into the past word).
    pub(super) fn sample(
        &self,
        word_pairs: &[(WordId, WordId)],
        anchors: &[i64],
        dir: Direction,
        reason: Rejection,
    ) -> RejectedCandidate {
        let (newest, oldest) = (word_pairs.len() - 1, 0);
        let (q, p) = self.sample_pair(word_pairs[newest], anchors[newest], dir);
        let (q0, p0) = self.sample_pair(word_pairs[oldest], anchors[oldest], dir);
        RejectedCandidate::new(q, p, dir, reason.index()).with_oldest(q0, p0)
    }

    /// The middle observation of current word `c` and the past observation shift `anchor`
    /// aligns with it (clamped into past word `p`).
    fn sample_pair(&self, (c, p): (WordId, WordId), anchor: i64, dir: Direction) -> (ObsId, ObsId) {
        let (cw, pw) = (self.word(c), self.word(p));
        let i = cw.size as i64 / 2;
        let j = (i + anchor).clamp(0, (pw.size as i64 - 1).max(0));
        let obs = self.words.observations();
        (
            obs[cw.first_obs + i as usize].id,
            obs[super::align::PastSide::of(pw, dir).index(j)].id,
        )
    }
}
