//! PCA, k-means and Kambhatla-Leen local PCA that stay exact on hard data (thesis §2.7).
