//! File-name patterns: `*` for any run of characters, `?` for one, every
//! other character itself (case-sensitive), matched against a whole name.

/// Whether `name` matches `pattern`.
pub fn matches(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    // Greedy with backtracking to the last `*`: linear in practice.
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some((i, j));
            i += 1;
        } else if let Some((si, sj)) = star {
            i = si + 1;
            j = sj + 1;
            star = Some((si, sj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::matches;

    #[test]
    fn stars_and_question_marks() {
        assert!(matches("IMG_6955.JPG", "IMG_6955.JPG"));
        assert!(!matches("IMG_6955.JPG", "IMG_6956.JPG"));
        assert!(matches("IMG_69*.JPG", "IMG_6955.JPG"));
        assert!(matches("*", "anything"));
        assert!(matches("SKY_??.jpg", "SKY_01.jpg"));
        assert!(!matches("SKY_??.jpg", "SKY_001.jpg"));
        assert!(matches("*a*b", "xaxxb"));
        assert!(!matches("*a*b", "xaxxbc"));
        assert!(!matches("IMG*", "img_1"));
    }
}
